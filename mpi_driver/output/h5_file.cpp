#include "mpi_driver/output/h5_file.hpp"

#include <hdf5_hl.h>
#include <algorithm>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/version.hpp"

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

/// Why the last HDF5 call on the file `path` failed, from its error stack: the system's reason
/// where the library gives one (e.g. "No space left on device"), else its innermost
/// description. The stack does not always carry the system's reason (a write the library
/// buffered fails later, without errno): a full file system is then said from its free space.
std::string hdf5_error_reason(const std::string& path) {
    struct Found {
        std::string innermost, system;
    } found;
    H5Ewalk2(
        H5E_DEFAULT, H5E_WALK_UPWARD,
        [](unsigned n, const H5E_error2_t* e, void* data) -> herr_t {
            auto& f = *static_cast<Found*>(data);
            const std::string desc = e->desc ? e->desc : "";
            if (n == 0) f.innermost = desc;
            const auto at = desc.find("error message = '");
            if (f.system.empty() && at != std::string::npos) {
                const auto start = at + 17, end = desc.find('\'', start);
                f.system =
                    desc.substr(start, end == std::string::npos ? std::string::npos : end - start);
            }
            return 0;
        },
        &found);
    H5Eclear2(H5E_DEFAULT);
    std::string reason = !found.system.empty() ? found.system : found.innermost;
    if (reason.find("No space left") != std::string::npos ||
        reason.find("quota") != std::string::npos)
        return reason + " (no space left: the disk or the quota is full)";
    const std::filesystem::path parent = std::filesystem::path(path).parent_path();
    std::error_code ec;
    const auto space = std::filesystem::space(parent.empty() ? "." : parent, ec);
    if (ec || space.available >= (1u << 20)) return reason;
    return fmt::format(
        "{}{}no space left: {} bytes free on its file system (the disk or the quota is full)",
        reason, reason.empty() ? "" : "; ", space.available);
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
    if (f < 0) {
        const std::string why = hdf5_error_reason(path.string());
        throw RuntimeFailure(fmt::format("cannot create the HDF5 file {}{}{}", path.string(),
                                         why.empty() ? "" : ": ", why));
    }
    return H5File(f, path.string());
}

H5File H5File::open(const std::filesystem::path& path, bool writable) {
    silence_hdf5();
    const hid_t f =
        H5Fopen(path.string().c_str(), writable ? H5F_ACC_RDWR : H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        throw RuntimeFailure(fmt::format(
            "cannot open {} as an HDF5 file (missing, truncated or not HDF5)", path.string()));
    return H5File(f, path.string());
}

H5File H5File::open_image(const std::string& bytes, const std::string& name) {
    silence_hdf5();
    const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    hid_t f = -1;
    // The core driver reads from a copy of the image and never writes it back (backing store 0).
    if (fapl >= 0 && H5Pset_fapl_core(fapl, 1 << 16, 0) >= 0 &&
        H5Pset_file_image(fapl, const_cast<char*>(bytes.data()), bytes.size()) >= 0)
        f = H5Fopen(name.c_str(), H5F_ACC_RDONLY, fapl);
    if (fapl >= 0) H5Pclose(fapl);
    if (f < 0)
        throw RuntimeFailure(
            fmt::format("cannot read {} as an HDF5 file ({} bytes)", name, bytes.size()));
    return H5File(f, name);
}

H5File::~H5File() {
    if (file_ >= 0) H5Fclose(file_);
}

H5File::H5File(H5File&& other) noexcept : file_(other.file_), path_(std::move(other.path_)) {
    other.file_ = -1;
}

void H5File::check(herr_t status, const std::string& what) const {
    if (status < 0) {
        const std::string why = hdf5_error_reason(path_);
        throw RuntimeFailure(
            fmt::format("HDF5 error in {}: {}{}{}", path_, what, why.empty() ? "" : ": ", why));
    }
}

hid_t H5File::check_id(hid_t id, const std::string& what) const {
    if (id < 0) {
        const std::string why = hdf5_error_reason(path_);
        throw RuntimeFailure(
            fmt::format("HDF5 error in {}: {}{}{}", path_, what, why.empty() ? "" : ": ", why));
    }
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
    if (H5Aexists(obj, name.c_str()) > 0) H5Adelete(obj, name.c_str());  // rewrite: replace
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
    const herr_t status = attr < 0 ? -1 : write(attr);
    if (attr >= 0) H5Aclose(attr);
    H5Sclose(space);
    H5Oclose(obj);
    f.check(status, "write attribute " + object + "@" + name);
}
}  // namespace

void H5File::attribute(const std::string& object, const std::string& name,
                       const std::string& value) {
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

void H5File::write_build_provenance() {
    attribute("/", "efdem_version", version());
    attribute("/", "git_hash", git_hash());
    attribute("/", "build", build_info());
}

void H5File::write_text(const std::string& name, const std::string& text) {
    const hid_t t = string_type();
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t d =
        check_id(H5Dcreate2(file_, name.c_str(), t, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                 "create dataset " + name);
    const char* p = text.c_str();
    const herr_t status = H5Dwrite(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, &p);
    H5Dclose(d);
    H5Sclose(space);
    H5Tclose(t);
    check(status, "write dataset " + name);
}

namespace {
void write_fixed(const H5File& f, const std::string& name, hid_t type, const void* data,
                 const std::vector<hsize_t>& shape) {
    const hid_t space = H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr);
    const hid_t d = f.check_id(
        H5Dcreate2(f.id(), name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        "create dataset " + name);
    hsize_t n = 1;
    for (hsize_t s : shape) n *= s;
    const herr_t status = n == 0 ? 0 : H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    H5Dclose(d);
    H5Sclose(space);
    f.check(status, "write dataset " + name);
}

/// Reads rows [first, first + count) of `name` (count clipped to the rows there are).
template <class T>
std::vector<T> read_rows(const H5File& f, const std::string& name, hid_t memtype, hsize_t first,
                         hsize_t count) {
    const hid_t d = f.check_id(H5Dopen2(f.id(), name.c_str(), H5P_DEFAULT), "open dataset " + name);
    const hid_t fspace = H5Dget_space(d);
    const int rank = H5Sget_simple_extent_ndims(fspace);
    std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
    if (rank > 0) H5Sget_simple_extent_dims(fspace, dims.data(), nullptr);
    if (rank == 0) dims = {1};
    herr_t status = rank < 0 ? -1 : 0;
    std::vector<T> out;
    if (status >= 0 && first > dims[0]) status = -1;
    if (status >= 0) {
        count = std::min(count, dims[0] - first);
        std::vector<hsize_t> start(dims.size(), 0), cnt = dims;
        start[0] = first;
        cnt[0] = count;
        hsize_t n = 1;
        for (hsize_t c : cnt) n *= c;
        out.resize(static_cast<std::size_t>(n));
        if (n > 0) {
            if (rank > 0)
                H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start.data(), nullptr, cnt.data(),
                                    nullptr);
            const hid_t mspace =
                rank > 0 ? H5Screate_simple(static_cast<int>(cnt.size()), cnt.data(), nullptr)
                         : H5Screate(H5S_SCALAR);
            status = H5Dread(d, memtype, mspace, fspace, H5P_DEFAULT, out.data());
            H5Sclose(mspace);
        }
    }
    H5Sclose(fspace);
    H5Dclose(d);
    f.check(status, "read dataset " + name);
    return out;
}
}  // namespace

void H5File::write(const std::string& name, std::span<const double> data,
                   std::vector<hsize_t> shape) {
    write_fixed(*this, name, H5T_NATIVE_DOUBLE, data.data(), shape);
}

void H5File::write(const std::string& name, std::span<const std::int64_t> data,
                   std::vector<hsize_t> shape) {
    write_fixed(*this, name, H5T_NATIVE_INT64, data.data(), shape);
}

void H5File::write_bytes(const std::string& name, std::span<const std::uint8_t> data) {
    write_fixed(*this, name, H5T_NATIVE_UINT8, data.data(), {static_cast<hsize_t>(data.size())});
}

void H5File::write_texts(const std::string& name, const std::vector<std::string>& texts) {
    std::vector<const char*> p;
    for (const auto& t : texts) p.push_back(t.c_str());
    const hid_t t = string_type();
    write_fixed(*this, name, t, p.data(), {static_cast<hsize_t>(p.size())});
    H5Tclose(t);
}

void H5File::document(const std::string& name, const std::string& units,
                      const std::string& long_name, const std::string& description,
                      const std::vector<std::string>& labels,
                      const std::vector<std::string>& scales) {
    attribute(name, "units", units);
    attribute(name, "long_name", long_name);
    attribute(name, "description", description);
    if (labels.empty()) return;
    const hid_t d = check_id(H5Dopen2(file_, name.c_str(), H5P_DEFAULT), "open " + name);
    herr_t status = 0;
    for (std::size_t i = 0; i < labels.size() && status >= 0; ++i) {
        const auto dim = static_cast<unsigned>(i);
        status = H5DSset_label(d, dim, labels[i].c_str());
        if (status < 0 || i >= scales.size() || scales[i].empty()) continue;
        if (scales[i] == name) {
            status = H5DSset_scale(d, labels[i].c_str());
        } else if (exists(scales[i])) {
            const hid_t scale = H5Dopen2(file_, scales[i].c_str(), H5P_DEFAULT);
            status = scale < 0 ? -1 : H5DSis_scale(scale) > 0 ? H5DSattach_scale(d, scale, dim) : 0;
            if (scale >= 0) H5Dclose(scale);
        }
    }
    H5Dclose(d);
    check(status, "dimension scales of " + name);
}

void H5File::strip_dimension_scales() {
    std::vector<std::string> links, datasets;
    check(H5Lvisit(
              file_, H5_INDEX_NAME, H5_ITER_INC,
              [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
                  static_cast<std::vector<std::string>*>(data)->push_back(name);
                  return 0;
              },
              &links),
          "list the file's objects");
    for (const std::string& name : links) {
        const hid_t obj = check_id(H5Oopen(file_, name.c_str(), H5P_DEFAULT), "open " + name);
        if (H5Iget_type(obj) == H5I_DATASET) datasets.push_back(name);
        H5Oclose(obj);
    }
    for (const std::string& name : datasets)
        for (const char* attr :
             {"DIMENSION_LIST", "REFERENCE_LIST", "DIMENSION_LABELS", "CLASS", "NAME"})
            if (has_attribute(name, attr))
                check(H5Adelete_by_name(file_, name.c_str(), attr, H5P_DEFAULT),
                      fmt::format("remove the dimension scale attribute {}@{}", name, attr));
}

void H5File::move(const std::string& from, const std::string& to) {
    check(H5Lmove(file_, from.c_str(), file_, to.c_str(), H5P_DEFAULT, H5P_DEFAULT),
          fmt::format("rename {} to {}", from, to));
}

bool H5File::exists(const std::string& name) const {
    return H5Lexists(file_, name.c_str(), H5P_DEFAULT) > 0;
}

bool H5File::has_attribute(const std::string& object, const std::string& name) const {
    return H5Aexists_by_name(file_, object.c_str(), name.c_str(), H5P_DEFAULT) > 0;
}

std::int64_t H5File::attribute_integer(const std::string& object, const std::string& name) const {
    std::int64_t v = 0;
    const hid_t a =
        check_id(H5Aopen_by_name(file_, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
                 "open attribute " + object + "@" + name);
    const herr_t status = H5Aread(a, H5T_NATIVE_INT64, &v);
    H5Aclose(a);
    check(status, "read attribute " + object + "@" + name);
    return v;
}

std::string H5File::attribute_text(const std::string& object, const std::string& name) const {
    const hid_t a =
        check_id(H5Aopen_by_name(file_, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
                 "open attribute " + object + "@" + name);
    const hid_t t = string_type();
    char* p = nullptr;
    const herr_t status = H5Aread(a, t, &p);
    std::string out = status >= 0 && p ? std::string(p) : std::string();
    if (status >= 0 && p) H5free_memory(p);
    H5Tclose(t);
    H5Aclose(a);
    check(status, "read attribute " + object + "@" + name);
    return out;
}

std::vector<hsize_t> H5File::shape(const std::string& name) const {
    const hid_t d = check_id(H5Dopen2(file_, name.c_str(), H5P_DEFAULT), "open dataset " + name);
    const hid_t space = H5Dget_space(d);
    const int rank = H5Sget_simple_extent_ndims(space);
    std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
    if (rank > 0) H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    H5Sclose(space);
    H5Dclose(d);
    check(rank < 0 ? -1 : 0, "read the shape of " + name);
    return dims;
}

std::vector<double> H5File::read_doubles(const std::string& name, hsize_t first,
                                         hsize_t count) const {
    return read_rows<double>(*this, name, H5T_NATIVE_DOUBLE, first, count);
}

std::vector<std::int64_t> H5File::read_integers(const std::string& name, hsize_t first,
                                                hsize_t count) const {
    return read_rows<std::int64_t>(*this, name, H5T_NATIVE_INT64, first, count);
}

std::vector<std::uint8_t> H5File::read_bytes(const std::string& name, hsize_t first,
                                             hsize_t count) const {
    return read_rows<std::uint8_t>(*this, name, H5T_NATIVE_UINT8, first, count);
}

std::vector<std::string> H5File::members(const std::string& group) const {
    H5G_info_t info{};
    check(H5Gget_info_by_name(file_, group.c_str(), &info, H5P_DEFAULT), "read group " + group);
    std::vector<std::string> out;
    for (hsize_t k = 0; k < info.nlinks; ++k) {
        const ssize_t n = H5Lget_name_by_idx(file_, group.c_str(), H5_INDEX_NAME, H5_ITER_INC, k,
                                             nullptr, 0, H5P_DEFAULT);
        check(n < 0 ? -1 : 0, "list group " + group);
        std::string name(static_cast<std::size_t>(n) + 1, '\0');
        H5Lget_name_by_idx(file_, group.c_str(), H5_INDEX_NAME, H5_ITER_INC, k, name.data(),
                           name.size(), H5P_DEFAULT);
        name.resize(static_cast<std::size_t>(n));
        out.push_back(std::move(name));
    }
    return out;
}

std::string H5File::read_text(const std::string& name) const {
    const hid_t d = check_id(H5Dopen2(file_, name.c_str(), H5P_DEFAULT), "open dataset " + name);
    const hid_t t = string_type();
    char* p = nullptr;
    const herr_t status = H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, &p);
    std::string out = status >= 0 && p ? std::string(p) : std::string();
    if (status >= 0 && p) H5free_memory(p);
    H5Tclose(t);
    H5Dclose(d);
    check(status, "read dataset " + name);
    return out;
}

void H5File::flush() {
    check(H5Fflush(file_, H5F_SCOPE_GLOBAL), "flush");
}

// ---------------------------------------------------------------------------------------------

H5Series::H5Series(H5File& file, const std::string& name, std::vector<hsize_t> row_shape, Type type)
    : file_(&file), name_(name), row_shape_(std::move(row_shape)) {
    for (hsize_t d : row_shape_) row_size_ *= d;
    type_ = type == Type::real      ? H5Tcopy(H5T_NATIVE_DOUBLE)
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

H5Series H5Series::open(H5File& file, const std::string& name, Type type) {
    H5Series s;
    s.file_ = &file;
    s.name_ = name;
    s.dset_ = file.check_id(H5Dopen2(file.id(), name.c_str(), H5P_DEFAULT), "open series " + name);
    s.type_ = type == Type::real      ? H5Tcopy(H5T_NATIVE_DOUBLE)
              : type == Type::integer ? H5Tcopy(H5T_NATIVE_INT64)
                                      : string_type();
    const hid_t space = H5Dget_space(s.dset_);
    const int rank = H5Sget_simple_extent_ndims(space);
    std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 1)), 0);
    if (rank > 0) H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    H5Sclose(space);
    s.rows_ = dims[0];
    s.row_shape_.assign(dims.begin() + 1, dims.end());
    for (hsize_t d : s.row_shape_) s.row_size_ *= d;
    return s;
}

H5Series::~H5Series() {
    if (dset_ >= 0) H5Dclose(dset_);
    if (type_ >= 0) H5Tclose(type_);
}

H5Series::H5Series(H5Series&& o) noexcept
    : file_(o.file_),
      name_(std::move(o.name_)),
      row_shape_(std::move(o.row_shape_)),
      row_size_(o.row_size_),
      dset_(o.dset_),
      type_(o.type_),
      rows_(o.rows_) {
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
