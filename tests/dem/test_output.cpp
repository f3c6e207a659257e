// VTK series and thermo log: the files exist, are complete, and hold what was written.
#include <catch2/catch.hpp>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "dem/io/thermo_log.hpp"
#include "dem/io/vtk_writer.hpp"
#include "tests/support/csv_table.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {
using test::slurp;

System three_particles() {
    const auto species = test::binary_species();
    Particles p;
    p.add(7, {1, 1, 1}, {0.5, 0, 0}, 0, species);
    p.add(8, {2.2, 1, 1}, {0, 0, 0}, 1, species);
    p.add(9, {1, 2.5, 3}, {0, 0, -1}, 1, species);
    test::EffectList fx;
    fx.gravity().pair(test::paper_contact(), species).wall(test::paper_contact(), species);
    return test::make_system(species, {5, 5}, std::move(p), std::move(fx), 1e-4);
}

/// The values of array `name` of a .vtp file written with raw appended data and UInt64 block
/// headers, read the way a VTK reader does: the DataArray's offset counts from the byte after
/// the '_' that opens the appended data; there a UInt64 byte count precedes the values.
template <class T>
std::vector<T> appended_array(const std::string& vtp, const std::string& name) {
    const std::size_t element = vtp.find("Name=\"" + name + "\"");
    REQUIRE(element != std::string::npos);
    const std::size_t at = vtp.find("offset=\"", element) + 8;
    const std::size_t offset = std::stoul(vtp.substr(at, vtp.find('"', at) - at));
    const std::size_t start = vtp.find("<AppendedData encoding=\"raw\">");
    REQUIRE(start != std::string::npos);
    const std::size_t block = vtp.find('_', start) + 1 + offset;
    std::uint64_t bytes = 0;
    REQUIRE(block + sizeof bytes <= vtp.size());
    std::memcpy(&bytes, vtp.data() + block, sizeof bytes);
    REQUIRE(bytes % sizeof(T) == 0);
    REQUIRE(block + sizeof bytes + bytes <= vtp.size());
    std::vector<T> values(bytes / sizeof(T));
    std::memcpy(values.data(), vtp.data() + block + sizeof bytes, bytes);
    return values;
}
}  // namespace

TEST_CASE("the VTK series writes one .vtp per snapshot and a .pvd that lists them", "[unit][io]") {
    const auto dir = std::filesystem::temp_directory_path() / "efdem_vtk_test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    System s = three_particles();
    VtkSeriesWriter w(dir, "bed");
    w.write(s);
    s.run(10);
    w.write(s);
    CHECK(w.snapshots() == 2);
    const std::string pvd = slurp(dir / "bed.pvd");
    CHECK(pvd.find("file=\"bed_000000.vtp\"") != std::string::npos);
    CHECK(pvd.find("timestep=\"0.001\" part=\"0\" file=\"bed_000001.vtp\"") != std::string::npos);
    const std::string vtp = slurp(dir / "bed_000001.vtp");
    const char* order = std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
    CHECK(vtp.find(fmt::format("byte_order=\"{}\" header_type=\"UInt64\"", order)) !=
          std::string::npos);
    CHECK(vtp.find("NumberOfPoints=\"3\" NumberOfVerts=\"3\"") != std::string::npos);
    CHECK(vtp.find("format=\"ascii\"") == std::string::npos);
    CHECK(vtp.substr(vtp.size() - 30).find("</AppendedData>\n</VTKFile>\n") != std::string::npos);
    // The tag array holds the permanent ids (7, 8, 9) in the current particle order; species
    // the index into species_names (light, heavy); each particle is its own vertex cell.
    const Particles& p = s.particles();
    const auto tags = appended_array<std::int64_t>(vtp, "tag");
    CHECK(std::vector<std::int64_t>(p.tag().begin(), p.tag().end()) == tags);
    CHECK(
        std::is_permutation(tags.begin(), tags.end(), std::vector<std::int64_t>{7, 8, 9}.begin()));
    CHECK(appended_array<std::int32_t>(vtp, "species") ==
          std::vector<std::int32_t>(p.species().begin(), p.species().end()));
    CHECK(appended_array<std::int64_t>(vtp, "connectivity") == std::vector<std::int64_t>{0, 1, 2});
    CHECK(appended_array<std::int64_t>(vtp, "offsets") == std::vector<std::int64_t>{1, 2, 3});
    const auto names = appended_array<char>(vtp, "species_names");
    CHECK(std::string(names.begin(), names.end()) == std::string("light\0heavy\0", 12));
    // Float64 values are the doubles themselves (no decimal rounding): the positions and time
    // compare exactly with the System's.
    const auto x = appended_array<double>(vtp, "position");
    REQUIRE(x.size() == 9);
    for (std::size_t i = 0; i < 3; ++i) {
        CHECK(x[3 * i] == p.x()[i].x);
        CHECK(x[3 * i + 2] == p.x()[i].z);
    }
    CHECK(appended_array<double>(vtp, "TimeValue") == std::vector<double>{s.time()});
    const auto r = appended_array<double>(vtp, "radius");
    const auto d = appended_array<double>(vtp, "diameter");
    REQUIRE(r.size() == 3);
    REQUIRE(d.size() == 3);
    for (std::size_t i = 0; i < 3; ++i) CHECK(d[i] == 2 * r[i]);
    for (const char* name : {"velocity", "angular_velocity", "mass"})
        CHECK(appended_array<double>(vtp, name).size() == (std::string(name) == "mass" ? 3u : 9u));
}

TEST_CASE("the thermo log is CSV as pandas reads it: column names first, one row per call",
          "[unit][io]") {
    const auto file = std::filesystem::temp_directory_path() / "efdem_thermo_test.csv";
    System s = three_particles();
    {
        ThermoLog log(file);
        log.write(s);
        s.run(100);
        log.write(s);
    }
    const test::CsvTable t = test::read_csv_table(file);
    CHECK(t.header == std::vector<std::string>{"step", "time", "ke_trans_per_particle",
                                               "ke_rot_per_particle", "contacts_per_particle",
                                               "wall_contacts", "max_overlap", "neighbor_builds"});
    REQUIRE(t.rows.size() == 2);
    CHECK(t.ragged_rows() == 0);
    CHECK(t.rows.back()[0] == "100");
    // time = 100 steps of dt = 1e-4, printed with 10 significant digits.
    CHECK(std::stod(t.rows.back()[1]) == Approx(0.01).epsilon(1e-9));
    CHECK_THROWS_AS(ThermoLog("/nonexistent_dir/x.csv"), RuntimeFailure);
}

TEST_CASE("a full disk under the thermo log is a runtime failure that says no space left",
          "[unit][output]") {
    // /dev/full accepts the open and fails every write with ENOSPC: what a full disk does to a
    // log that is flushed after every line.
    if (!std::filesystem::exists("/dev/full")) {
        WARN("no /dev/full on this system: not tested");
        return;
    }
    try {
        ThermoLog log("/dev/full");
        FAIL("expected a RuntimeFailure");
    } catch (const RuntimeFailure& e) {
        CHECK_THAT(std::string(e.what()),
                   Catch::Contains("cannot write the thermo log /dev/full") &&
                       Catch::Contains("no space left: the disk or the quota is full"));
    }
}

TEST_CASE("a VTK frame that cannot be written leaves neither the frame nor its .tmp",
          "[unit][output]") {
    // The frame is written to NAME.tmp and renamed: writing into a directory that does not exist
    // fails before anything is left under NAME.
    const auto dir = std::filesystem::temp_directory_path() / "efdem_vtk_missing_dir_test";
    std::filesystem::remove_all(dir);
    const System sys = three_particles();
    CHECK_THROWS_AS(write_vtp(dir / "frame.vtp", sys), RuntimeFailure);
    CHECK_FALSE(std::filesystem::exists(dir / "frame.vtp"));
    CHECK_FALSE(std::filesystem::exists(dir / "frame.vtp.tmp"));
}
