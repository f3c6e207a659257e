// VTK series and thermo log: the files exist, are complete, and hold what was written.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "dem/io/thermo_log.hpp"
#include "dem/io/vtk_writer.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {
std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

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
    CHECK(vtp.find("NumberOfPoints=\"3\"") != std::string::npos);
    for (const char* name : {"velocity", "angular_velocity", "radius", "mass", "species", "tag"})
        CHECK(vtp.find(std::string("Name=\"") + name + "\"") != std::string::npos);
    CHECK(vtp.find("</VTKFile>") != std::string::npos);
    // The tag array holds the permanent ids (in the current particle order).
    CHECK(vtp.find("\n7\n") != std::string::npos);
    CHECK(vtp.find("\n9\n") != std::string::npos);
}

TEST_CASE("the thermo log writes a header and one line per call", "[unit][io]") {
    const auto file = std::filesystem::temp_directory_path() / "efdem_thermo_test.log";
    System s = three_particles();
    {
        ThermoLog log(file);
        log.write(s);
        s.run(100);
        log.write(s);
    }
    std::ifstream in(file);
    std::string line;
    int header = 0, rows = 0;
    long last_step = -1;
    while (std::getline(in, line)) {
        if (line.rfind("#", 0) == 0) {
            ++header;
            continue;
        }
        std::istringstream ss(line);
        ss >> last_step;
        ++rows;
    }
    CHECK(header == 2);
    CHECK(rows == 2);
    CHECK(last_step == 100);
    CHECK_THROWS_AS(ThermoLog("/nonexistent_dir/x.log"), RuntimeFailure);
}

TEST_CASE("a full disk under the thermo log is a runtime failure that says no space left", "[unit][output]") {
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
        CHECK_THAT(std::string(e.what()), Catch::Contains("cannot write the thermo log /dev/full") &&
                                              Catch::Contains("no space left: the disk or the quota is full"));
    }
}

TEST_CASE("a VTK frame that cannot be written leaves neither the frame nor its .tmp", "[unit][output]") {
    // The frame is written to NAME.tmp and renamed: writing into a directory that does not exist
    // fails before anything is left under NAME.
    const auto dir = std::filesystem::temp_directory_path() / "efdem_vtk_missing_dir_test";
    std::filesystem::remove_all(dir);
    const System sys = three_particles();
    CHECK_THROWS_AS(write_vtp(dir / "frame.vtp", sys.particles()), RuntimeFailure);
    CHECK_FALSE(std::filesystem::exists(dir / "frame.vtp"));
    CHECK_FALSE(std::filesystem::exists(dir / "frame.vtp.tmp"));
}
