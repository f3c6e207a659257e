#include "dem/io/vtk_writer.hpp"

#include <fstream>

#include <fmt/format.h>
#include <fmt/os.h>

#include "core/error.hpp"

namespace efdem::dem {

namespace {
template <class F>
void data_array(fmt::ostream& out, const char* type, const char* name, int components,
                std::size_t n, F&& value_of) {
    out.print("        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"ascii\">\n",
              type, name, components);
    for (std::size_t i = 0; i < n; ++i) out.print("{}\n", value_of(i));
    out.print("        </DataArray>\n");
}
std::string vec(const Vec3& v) { return fmt::format("{:.9g} {:.9g} {:.9g}", v.x, v.y, v.z); }
}  // namespace

void write_vtp(const std::filesystem::path& file, const Particles& p) {
    try {
        auto out = fmt::output_file(file.string());
        const std::size_t n = p.size();
        out.print("<?xml version=\"1.0\"?>\n"
                  "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
                  "  <PolyData>\n"
                  "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"0\" "
                  "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n"
                  "      <Points>\n", n);
        data_array(out, "Float64", "position", 3, n, [&](std::size_t i) { return vec(p.x()[i]); });
        out.print("      </Points>\n      <PointData Scalars=\"species\" Vectors=\"velocity\">\n");
        data_array(out, "Float64", "velocity", 3, n, [&](std::size_t i) { return vec(p.v()[i]); });
        data_array(out, "Float64", "angular_velocity", 3, n, [&](std::size_t i) { return vec(p.omega()[i]); });
        data_array(out, "Float64", "radius", 1, n, [&](std::size_t i) { return fmt::format("{:.9g}", p.radius()[i]); });
        data_array(out, "Float64", "mass", 1, n, [&](std::size_t i) { return fmt::format("{:.9g}", p.mass()[i]); });
        data_array(out, "Int32", "species", 1, n, [&](std::size_t i) { return fmt::format("{}", int{p.species()[i]}); });
        data_array(out, "Int64", "tag", 1, n, [&](std::size_t i) { return fmt::format("{}", p.tag()[i]); });
        out.print("      </PointData>\n    </Piece>\n  </PolyData>\n</VTKFile>\n");
        out.close();
    } catch (const std::exception& e) {
        throw RuntimeFailure(fmt::format("cannot write VTK file {}: {}", file.string(), e.what()));
    }
}

VtkSeriesWriter::VtkSeriesWriter(std::filesystem::path directory, std::string stem)
    : directory_(std::move(directory)), stem_(std::move(stem)), pvd_(directory_ / (stem_ + ".pvd")) {}

void VtkSeriesWriter::write(const System& system) {
    const std::string name = fmt::format("{}_{:06d}.vtp", stem_, entries_.size());
    write_vtp(directory_ / name, system.particles());
    entries_.emplace_back(system.time(), name);
    const auto tmp = pvd_.string() + ".tmp";
    {
        std::ofstream out(tmp);
        out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
        for (const auto& [t, f] : entries_)
            out << fmt::format("    <DataSet timestep=\"{:.9g}\" part=\"0\" file=\"{}\"/>\n", t, f);
        out << "  </Collection>\n</VTKFile>\n";
        if (!out) throw RuntimeFailure("cannot write " + tmp);
    }
    std::error_code ec;
    std::filesystem::rename(tmp, pvd_, ec);
    if (ec) throw RuntimeFailure(fmt::format("cannot rename {} to {}: {}", tmp, pvd_.string(), ec.message()));
}

}  // namespace efdem::dem
