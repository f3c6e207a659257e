#include "dem/io/vtk_writer.hpp"

#include <bit>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <string_view>

#include <fmt/format.h>

#include "core/io_error.hpp"

namespace efdem::dem {

namespace {
static_assert(std::endian::native == std::endian::little || std::endian::native == std::endian::big,
              "VTK files know only little- and big-endian byte orders");
constexpr const char* kByteOrder =
    std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
using BlockSize = std::uint64_t;  ///< header_type="UInt64": the byte count before each block

/// One data array of a .vtp file: where it goes, its XML attributes, and its raw values (in
/// the machine's byte order) for the appended block.
struct Array {
    const char* type;
    std::string name;
    int components = 1;
    std::size_t tuples = 0;
    std::string bytes;
};

template <class T>
void put(std::string& bytes, T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    bytes.append(raw, sizeof(T));
}

/// A one-component array of type `T` (VTK name `type`) with `value_of(i)` for i < n.
template <class T, class F>
Array scalars(const char* type, std::string name, std::size_t n, F&& value_of) {
    Array a{type, std::move(name), 1, n, {}};
    a.bytes.reserve(n * sizeof(T));
    for (std::size_t i = 0; i < n; ++i) put<T>(a.bytes, static_cast<T>(value_of(i)));
    return a;
}

Array vectors(std::string name, std::span<const Vec3> v) {
    Array a{"Float64", std::move(name), 3, v.size(), {}};
    a.bytes.reserve(v.size() * 3 * sizeof(double));
    for (const Vec3& x : v) {
        put(a.bytes, x.x);
        put(a.bytes, x.y);
        put(a.bytes, x.z);
    }
    return a;
}

/// A String array as VTK writes one in binary: every string followed by a NUL.
Array strings(std::string name, const std::vector<std::string>& values) {
    Array a{"String", std::move(name), 1, values.size(), {}};
    for (const auto& s : values) a.bytes.append(s).push_back('\0');
    return a;
}

/// Appends the DataArray elements of `arrays` to `xml` (offsets into the appended data, which
/// grow by each block and its byte count) and their blocks to `data`.
void append_arrays(fmt::memory_buffer& xml, std::string& data, const std::vector<Array>& arrays,
                   bool field_data) {
    for (const Array& a : arrays) {
        fmt::format_to(std::back_inserter(xml), "        <DataArray type=\"{}\" Name=\"{}\" ",
                       a.type, a.name);
        if (field_data)
            fmt::format_to(std::back_inserter(xml), "NumberOfTuples=\"{}\" ", a.tuples);
        else
            fmt::format_to(std::back_inserter(xml), "NumberOfComponents=\"{}\" ", a.components);
        fmt::format_to(std::back_inserter(xml), "format=\"appended\" offset=\"{}\"/>\n",
                       data.size());
        put<BlockSize>(data, a.bytes.size());
        data += a.bytes;
    }
}
}  // namespace

void write_vtp(const std::filesystem::path& file, const System& system) {
    const Particles& p = system.particles();
    const std::size_t n = p.size();
    std::vector<std::string> names;
    for (std::size_t k = 0; k < system.species().size(); ++k)
        names.push_back(system.species()[static_cast<SpeciesId>(k)].name);
    const auto radius = p.radius();

    fmt::memory_buffer xml;
    auto out = std::back_inserter(xml);
    std::string data;
    fmt::format_to(
        out,
        "<?xml version=\"1.0\"?>\n"
        "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"{}\" header_type=\"UInt64\">\n"
        "  <PolyData>\n    <FieldData>\n",
        kByteOrder);
    const double time = system.time();
    append_arrays(xml, data,
                  {scalars<double>("Float64", "TimeValue", 1, [&](std::size_t) { return time; }),
                   strings("species_names", names)},
                  true);
    fmt::format_to(out,
                   "    </FieldData>\n"
                   "    <Piece NumberOfPoints=\"{0}\" NumberOfVerts=\"{0}\" NumberOfLines=\"0\" "
                   "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n"
                   "      <PointData Scalars=\"species\" Vectors=\"velocity\">\n",
                   n);
    append_arrays(
        xml, data,
        {vectors("velocity", p.v()), vectors("angular_velocity", p.omega()),
         scalars<double>("Float64", "radius", n, [&](std::size_t i) { return radius[i]; }),
         scalars<double>("Float64", "diameter", n, [&](std::size_t i) { return 2 * radius[i]; }),
         scalars<double>("Float64", "mass", n, [&](std::size_t i) { return p.mass()[i]; }),
         scalars<std::int32_t>("Int32", "species", n,
                               [&](std::size_t i) { return p.species()[i]; }),
         scalars<std::int64_t>("Int64", "tag", n, [&](std::size_t i) { return p.tag()[i]; })},
        false);
    fmt::format_to(out, "      </PointData>\n      <Points>\n");
    append_arrays(xml, data, {vectors("position", p.x())}, false);
    // One vertex cell per particle: cell i is point i.
    fmt::format_to(out, "      </Points>\n      <Verts>\n");
    append_arrays(
        xml, data,
        {scalars<std::int64_t>("Int64", "connectivity", n, [](std::size_t i) { return i; }),
         scalars<std::int64_t>("Int64", "offsets", n, [](std::size_t i) { return i + 1; })},
        false);
    fmt::format_to(
        out,
        "      </Verts>\n    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _");
    std::string bytes(xml.data(), xml.size());
    bytes += data;
    bytes += "\n  </AppendedData>\n</VTKFile>\n";
    write_whole_file(file, bytes, "the VTK file");
}

VtkSeriesWriter::VtkSeriesWriter(std::filesystem::path directory, std::string stem)
    : directory_(std::move(directory)),
      stem_(std::move(stem)),
      pvd_(directory_ / (stem_ + ".pvd")) {}

void VtkSeriesWriter::write(const System& system) {
    const std::string name = fmt::format("{}_{:06d}.vtp", stem_, entries_.size());
    write_vtp(directory_ / name, system);
    entries_.emplace_back(system.time(), name);
    std::string text =
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
    for (const auto& [t, f] : entries_)
        text += fmt::format("    <DataSet timestep=\"{:.10g}\" part=\"0\" file=\"{}\"/>\n", t, f);
    text += "  </Collection>\n</VTKFile>\n";
    write_whole_file(pvd_, text, "the VTK series file");
}

}  // namespace efdem::dem
