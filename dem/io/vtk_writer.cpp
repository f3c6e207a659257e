#include "dem/io/vtk_writer.hpp"

#include <cstdio>
#include <iterator>
#include <string_view>

#include <fmt/format.h>

#include <cerrno>
#include <system_error>

#include "core/error.hpp"
#include "core/io_error.hpp"

namespace efdem::dem {

namespace {
template <class F>
void data_array(fmt::memory_buffer& out, const char* type, const char* name, int components,
                std::size_t n, F&& value_of) {
    fmt::format_to(std::back_inserter(out),
                   "        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n",
                   type, name, components);
    for (std::size_t i = 0; i < n; ++i) fmt::format_to(std::back_inserter(out), "{}\n", value_of(i));
    fmt::format_to(std::back_inserter(out), "        </DataArray>\n");
}
std::string vec(const Vec3& v) { return fmt::format("{:.9g} {:.9g} {:.9g}", v.x, v.y, v.z); }

/// Writes `bytes` to `tmp`, then renames it to `file`: a file cut short (a full disk) is never
/// left under the name of a whole one. RuntimeFailure naming `file` (and no `tmp` left) if not.
void write_whole(const std::filesystem::path& file, const std::filesystem::path& tmp, std::string_view bytes,
                 const char* what) {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    int err = f ? 0 : errno;
    if (f) {
        if (std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size() || std::fflush(f) != 0) err = errno ? errno : EIO;
        if (std::fclose(f) != 0 && err == 0) err = errno ? errno : EIO;
    }
    std::error_code ec;
    if (err == 0) std::filesystem::rename(tmp, file, ec);
    if (err == 0 && ec) err = ec.value();
    if (err != 0) {
        std::filesystem::remove(tmp, ec);
        throw RuntimeFailure(io_failure_message(file, what, err));
    }
}
}  // namespace

void write_vtp(const std::filesystem::path& file, const Particles& p) {
    fmt::memory_buffer out;
    auto out_it = std::back_inserter(out);
    const std::size_t n = p.size();
    fmt::format_to(out_it, "<?xml version=\"1.0\"?>\n"
          "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
          "  <PolyData>\n"
          "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"0\" "
          "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n"
          "      <Points>\n", n);
    data_array(out, "Float64", "position", 3, n, [&](std::size_t i) { return vec(p.x()[i]); });
    fmt::format_to(out_it, "      </Points>\n      <PointData Scalars=\"species\" Vectors=\"velocity\">\n");
    data_array(out, "Float64", "velocity", 3, n, [&](std::size_t i) { return vec(p.v()[i]); });
    data_array(out, "Float64", "angular_velocity", 3, n, [&](std::size_t i) { return vec(p.omega()[i]); });
    data_array(out, "Float64", "radius", 1, n, [&](std::size_t i) { return fmt::format("{:.9g}", p.radius()[i]); });
    data_array(out, "Float64", "mass", 1, n, [&](std::size_t i) { return fmt::format("{:.9g}", p.mass()[i]); });
    data_array(out, "Int32", "species", 1, n, [&](std::size_t i) { return fmt::format("{}", int{p.species()[i]}); });
    data_array(out, "Int64", "tag", 1, n, [&](std::size_t i) { return fmt::format("{}", p.tag()[i]); });
    fmt::format_to(out_it, "      </PointData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n");
    write_whole(file, file.string() + ".tmp", std::string_view(out.data(), out.size()), "the VTK file");
}

VtkSeriesWriter::VtkSeriesWriter(std::filesystem::path directory, std::string stem)
    : directory_(std::move(directory)), stem_(std::move(stem)), pvd_(directory_ / (stem_ + ".pvd")) {}

void VtkSeriesWriter::write(const System& system) {
    const std::string name = fmt::format("{}_{:06d}.vtp", stem_, entries_.size());
    write_vtp(directory_ / name, system.particles());
    entries_.emplace_back(system.time(), name);
    std::string text = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
    for (const auto& [t, f] : entries_)
        text += fmt::format("    <DataSet timestep=\"{:.9g}\" part=\"0\" file=\"{}\"/>\n", t, f);
    text += "  </Collection>\n</VTKFile>\n";
    write_whole(pvd_, pvd_.string() + ".tmp", text, "the VTK series file");
}

}  // namespace efdem::dem
