#include "mpi_driver/h5_file.hpp"

#include <fmt/format.h>

#include "core/error.hpp"

namespace efdem::mpi_driver {

namespace {
/// HDF5 prints its own error stack to stderr by default; efdem reports errors itself.
void silence_hdf5() {
    static const bool done = [] {
        H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
        return true;
    }();
    (void)done;
}

hid_t string_type() {
    const hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, H5T_VARIABLE);
    H5Tset_cset(t, H5T_CSET_UTF8);
    return t;
}
}  // namespace

// ---------------------------------------------------------------------------------------------

H5File H5File::create(const std::filesystem::path& path) {
    silence_hdf5();
    const hid_t f = H5Fcreate(path.string().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (f < 0) throw RuntimeFailure(fmt::format("cannot create the HDF5 file {}", path.string()));
    return H5File(f, path.string());
}

H5File::~H5File() {
    if (file_ >= 0) H5Fclose(file_);
}

H5File::H5File(H5File&& other) noexcept : file_(other.file_), path_(std::move(other.path_)) {
    other.file_ = -1;
}

void H5File::check(herr_t status, const std::string& what) const {
    if (status < 0) throw RuntimeFailure(fmt::format("HDF5 error in {}: {}", path_, what));
}

hid_t H5File::check_id(hid_t id, const std::string& what) const {
    if (id < 0) throw RuntimeFailure(fmt::format("HDF5 error in {}: {}", path_, what));
    return id;
}

void H5File::create_group(const std::string& path) {
    const hid_t g = check_id(H5Gcreate2(file_, path.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                             "create group " + path);
    H5Gclose(g);
}

namespace {
template <class F>
void with_attribute(const H5File& f, const std::string& object, const std::string& name, hid_t type,
                    F&& write) {
    const hid_t obj = f.check_id(H5Oopen(f.id(), object.c_str(), H5P_DEFAULT), "open " + object);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
    const herr_t status = attr < 0 ? -1 : write(attr);
    if (attr >= 0) H5Aclose(attr);
    H5Sclose(space);
    H5Oclose(obj);
    f.check(status, "write attribute " + object + "@" + name);
}
}  // namespace

void H5File::attribute(const std::string& object, const std::string& name, const std::string& value) {
    const hid_t t = string_type();
    const char* p = value.c_str();
    with_attribute(*this, object, name, t, [&](hid_t a) { return H5Awrite(a, t, &p); });
    H5Tclose(t);
}

void H5File::attribute(const std::string& object, const std::string& name, double value) {
    with_attribute(*this, object, name, H5T_NATIVE_DOUBLE,
                   [&](hid_t a) { return H5Awrite(a, H5T_NATIVE_DOUBLE, &value); });
}

void H5File::attribute(const std::string& object, const std::string& name, std::int64_t value) {
    with_attribute(*this, object, name, H5T_NATIVE_INT64,
                   [&](hid_t a) { return H5Awrite(a, H5T_NATIVE_INT64, &value); });
}

void H5File::write(const std::string& name, std::span<const double> data, std::vector<hsize_t> shape) {
    const hid_t space = H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr);
    const hid_t d = check_id(H5Dcreate2(file_, name.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT,
                                        H5P_DEFAULT, H5P_DEFAULT),
                             "create dataset " + name);
    const herr_t status = H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data());
    H5Dclose(d);
    H5Sclose(space);
    check(status, "write dataset " + name);
}

void H5File::write_text(const std::string& name, const std::string& text) {
    const hid_t t = string_type();
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t d = check_id(H5Dcreate2(file_, name.c_str(), t, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                             "create dataset " + name);
    const char* p = text.c_str();
    const herr_t status = H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, &p);
    H5Dclose(d);
    H5Sclose(space);
    H5Tclose(t);
    check(status, "write dataset " + name);
}

void H5File::flush() { check(H5Fflush(file_, H5F_SCOPE_GLOBAL), "flush"); }

// ---------------------------------------------------------------------------------------------

H5Series::H5Series(H5File& file, const std::string& name, std::vector<hsize_t> row_shape, Type type)
    : file_(&file), name_(name), row_shape_(std::move(row_shape)) {
    for (hsize_t d : row_shape_) row_size_ *= d;
    type_ = type == Type::real ? H5Tcopy(H5T_NATIVE_DOUBLE)
            : type == Type::integer ? H5Tcopy(H5T_NATIVE_INT64)
                                    : string_type();
    std::vector<hsize_t> dims{0}, max{H5S_UNLIMITED}, chunk{64};
    for (hsize_t d : row_shape_) {
        dims.push_back(d);
        max.push_back(d);
        chunk.push_back(d);
    }
    // Keep chunks near 64 KiB: fewer rows per chunk for wide rows.
    chunk[0] = std::max<hsize_t>(1, std::min<hsize_t>(64, 8192 / std::max<hsize_t>(1, row_size_)));
    const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), max.data());
    const hid_t props = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(props, static_cast<int>(chunk.size()), chunk.data());
    dset_ = H5Dcreate2(file.id(), name.c_str(), type_, space, H5P_DEFAULT, props, H5P_DEFAULT);
    H5Pclose(props);
    H5Sclose(space);
    file.check_id(dset_, "create series " + name);
}

H5Series::~H5Series() {
    if (dset_ >= 0) H5Dclose(dset_);
    if (type_ >= 0) H5Tclose(type_);
}

H5Series::H5Series(H5Series&& o) noexcept
    : file_(o.file_), name_(std::move(o.name_)), row_shape_(std::move(o.row_shape_)),
      row_size_(o.row_size_), dset_(o.dset_), type_(o.type_), rows_(o.rows_) {
    o.dset_ = -1;
    o.type_ = -1;
}

void H5Series::extend_and_write(const void* data, hid_t memtype) {
    std::vector<hsize_t> dims{rows_ + 1}, start{rows_}, count{1};
    for (hsize_t d : row_shape_) {
        dims.push_back(d);
        start.push_back(0);
        count.push_back(d);
    }
    file_->check(H5Dset_extent(dset_, dims.data()), "extend " + name_);
    const hid_t fspace = H5Dget_space(dset_);
    H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr);
    const hid_t mspace = H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr);
    const herr_t status = H5Dwrite(dset_, memtype, mspace, fspace, H5P_DEFAULT, data);
    H5Sclose(mspace);
    H5Sclose(fspace);
    file_->check(status, "append to " + name_);
    ++rows_;
}

void H5Series::append(std::span<const double> row) {
    if (row.size() != row_size_)
        throw RuntimeFailure(fmt::format("{}: row of {} values appended to {} of row size {}",
                                         file_->path(), row.size(), name_, row_size_));
    extend_and_write(row.data(), H5T_NATIVE_DOUBLE);
}

void H5Series::append(std::span<const std::int64_t> row) {
    if (row.size() != row_size_)
        throw RuntimeFailure(fmt::format("{}: row of {} values appended to {} of row size {}",
                                         file_->path(), row.size(), name_, row_size_));
    extend_and_write(row.data(), H5T_NATIVE_INT64);
}

void H5Series::append_text(const std::string& text) {
    const char* p = text.c_str();
    extend_and_write(&p, type_);
}

}  // namespace efdem::mpi_driver
