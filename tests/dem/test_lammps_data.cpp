// The LAMMPS write_data reader on the reference bed (tests/data/packed_bed_12500.data.gz) and on
// broken files.
#include <catch2/catch.hpp>

#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "dem/io/lammps_data.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {
const std::filesystem::path kBed =
    std::filesystem::path(EFDEM_TEST_DATA_DIR) / "packed_bed_12500.data.gz";

std::filesystem::path write_text(const std::string& name, const std::string& text) {
    const auto path = std::filesystem::temp_directory_path() / name;
    std::ofstream(path) << text;
    return path;
}

std::string read_gz(const std::filesystem::path& path) {
    gzFile f = gzopen(path.string().c_str(), "rb");
    std::string out;
    char buf[1 << 16];
    int n;
    while ((n = gzread(f, buf, sizeof buf)) > 0) out.append(buf, static_cast<std::size_t>(n));
    gzclose(f);
    return out;
}
}  // namespace

TEST_CASE("the reference bed loads: 12,500 spheres, 6,250 of each species, the recorded heights",
          "[unit][io]") {
    const Particles p = read_lammps_data(kBed, test::binary_species(), Domain{15, 15, 150});
    REQUIRE(p.size() == 12500);
    double mean_z[2] = {0, 0};
    long count[2] = {0, 0};
    double top = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        mean_z[p.species()[i]] += p.x()[i].z;
        ++count[p.species()[i]];
        top = std::max(top, p.x()[i].z);
        REQUIRE(p.x()[i].x >= 0);
        REQUIRE(p.x()[i].x < 15);
    }
    CHECK(count[0] == 6250);
    CHECK(count[1] == 6250);
    // lammps_reference.md: mean height 23.869 (light), 23.875 (heavy), top particle at 48.04.
    CHECK(mean_z[0] / 6250 == Approx(23.869).margin(5e-4));
    CHECK(mean_z[1] / 6250 == Approx(23.875).margin(5e-4));
    CHECK(top == Approx(48.04).margin(0.01));
    CHECK(p.tag()[0] == 1);  // sorted by id
}

TEST_CASE("broken LAMMPS data files are input errors naming the file and the line", "[unit][io]") {
    const auto species = test::binary_species();
    const std::string header =
        "title\n\n3 atoms\n2 atom types\n\n0 4 xlo xhi\n0 4 ylo yhi\n0 10 zlo zhi\n\nAtoms # "
        "sphere\n\n";
    auto error_of = [&](const std::filesystem::path& path, const Domain& d) -> InputError {
        try {
            read_lammps_data(path, species, d);
        } catch (const InputError& e) {
            return e;
        }
        FAIL("expected an InputError");
        throw std::logic_error("unreachable");
    };
    const Domain d{4, 4};
    SECTION("missing file") {
        CHECK(error_of("/nonexistent/bed.data", d).problem().find("not found") !=
              std::string::npos);
    }
    SECTION("truncated: fewer atoms than announced") {
        const auto f =
            write_text("efdem_trunc.data", header + "1 1 1 1 0.5 0.5 0.5\n2 2 1 2 1.5 0.5 0.5\n");
        CHECK(error_of(f, d).problem().find("announces 3 atoms") != std::string::npos);
    }
    SECTION("a non-number") {
        const auto f = write_text("efdem_nan.data", header + "1 1 1 1 0.5 0.5 x\n");
        const auto e = error_of(f, d);
        CHECK(e.where().line == 12);
        CHECK(e.problem().find("'x'") != std::string::npos);
    }
    SECTION("a type with no species") {
        const auto f = write_text("efdem_type.data", header + "1 3 1 1 0.5 0.5 0.5\n");
        CHECK(error_of(f, d).problem().find("atom type 3 has no species") != std::string::npos);
    }
    SECTION("density that does not match the scene's species") {
        const auto f = write_text("efdem_rho.data", header + "1 2 1 3 0.5 0.5 0.5\n");
        CHECK(error_of(f, d).problem().find("species 'heavy'") != std::string::npos);
    }
    SECTION("box that does not match the domain") {
        const auto f =
            write_text("efdem_box.data",
                       header + "1 1 1 1 0.5 0.5 0.5\n2 1 1 1 1.5 0.5 0.5\n3 1 1 1 2.5 0.5 0.5\n");
        const auto e = error_of(f, Domain{5, 4});
        INFO(e.what());
        CHECK(e.problem().find("domain.lx = 5") != std::string::npos);
    }
    SECTION("counts, ids and types that no integer holds are refused, not converted") {
        // Found by the scene fuzzer: std::stol threw a non-input exception, and doubles beyond
        // the range of long were converted (undefined behaviour).
        auto problem = [&](const std::string& name, const std::string& text) {
            return error_of(write_text(name, text), d).problem();
        };
        std::string big = header;
        big.replace(big.find("3 atoms"), 7, "99999999999999999999 atoms");
        CHECK(problem("efdem_count.data", big).find("the number of atoms is 1e+20") !=
              std::string::npos);
        CHECK(problem("efdem_id.data", header + "1e300 1 1 1 0.5 0.5 0.5\n")
                  .find("the atom id is 1e+300") != std::string::npos);
        CHECK(problem("efdem_type.data", header + "1 2.5 1 1 0.5 0.5 0.5\n")
                  .find("the atom type is 2.5") != std::string::npos);
        CHECK(problem("efdem_vel.data",
                      header + "1 1 1 1 0.5 0.5 0.5\n\nVelocities\n\n-7e99 0 0 0 0 0 0\n")
                  .find("the atom id is -7e+99") != std::string::npos);
    }
    SECTION("an atom below the floor or above the lid") {
        const auto low =
            error_of(write_text("efdem_low.data", header + "1 1 1 1 0.5 0.5 -0.2\n"), d);
        CHECK(low.where().line == 12);
        CHECK(low.problem().find(
                  "atom 1 is at z = -0.2, outside the domain (allowed: 0 <= z <= 1e+06)") !=
              std::string::npos);
        const auto high = error_of(write_text("efdem_high.data", header + "1 1 1 1 0.5 0.5 9\n"),
                                   Domain{4, 4, 8});
        CHECK(high.problem().find("(allowed: 0 <= z <= 8)") != std::string::npos);
    }
    SECTION("a gzip stream cut in the middle") {
        const std::string whole = read_gz(kBed);
        const auto path = std::filesystem::temp_directory_path() / "efdem_cut.data.gz";
        gzFile g = gzopen(path.string().c_str(), "wb");
        gzwrite(g, whole.data(), static_cast<unsigned>(whole.size()));
        gzclose(g);
        const auto size = std::filesystem::file_size(path);
        std::filesystem::resize_file(path, size / 2);
        const auto e = error_of(path, Domain{15, 15, 150});
        CHECK(e.where().file == path.string());
    }
}

TEST_CASE("a written bed reads back bit for bit: positions (wrapped), velocities, spins, species",
          "[unit][io]") {
    const auto species = test::binary_species();
    const Domain d{4, 4, 20};
    Particles p = test::random_particles(50, 4, 0.5, 10, 7);
    // Tags out of order (the neighbour list sorts particles in space) and spins of any size;
    // two particles slightly outside the periodic box, as between neighbour-list rebuilds.
    for (std::size_t i = 0; i < p.size(); ++i)
        p.omega()[i] = {1e-17 * static_cast<double>(i), -3.0 / static_cast<double>(i + 1), 0.1};
    p.x()[3].x = -1e-3;
    p.x()[4].y = 4 + 2e-3;
    std::vector<Index> reverse(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) reverse[i] = static_cast<Index>(p.size() - 1 - i);
    p.permute(reverse);
    for (const std::string name : {"efdem_roundtrip.data", "efdem_roundtrip.data.gz"}) {
        const auto path = std::filesystem::temp_directory_path() / name;
        write_lammps_data(path, p, species, d, "round trip");
        const Particles q = read_lammps_data(path, species, d);
        REQUIRE(q.size() == p.size());
        for (std::size_t k = 0; k < q.size(); ++k) {
            const std::size_t i = p.size() - 1 - k;  // q is in tag order
            INFO(name << ": tag " << q.tag()[k]);
            REQUIRE(q.tag()[k] == p.tag()[i]);
            // Exact: 17 significant digits give every double back (std::stod rounds correctly).
            const Vec3 x = d.wrap(p.x()[i]);
            CHECK(q.x()[k].x == x.x);
            CHECK(q.x()[k].y == x.y);
            CHECK(q.x()[k].z == x.z);
            CHECK(q.v()[k].x == p.v()[i].x);
            CHECK(q.v()[k].y == p.v()[i].y);
            CHECK(q.v()[k].z == p.v()[i].z);
            CHECK(q.omega()[k].x == p.omega()[i].x);
            CHECK(q.omega()[k].y == p.omega()[i].y);
            CHECK(q.species()[k] == p.species()[i]);
        }
        CHECK(std::filesystem::exists(path));
        CHECK(!std::filesystem::exists(path.string() + ".tmp"));
    }
}

TEST_CASE("a written bed names its species; another species table is refused", "[unit][io]") {
    const auto species = test::binary_species();
    const auto path = std::filesystem::temp_directory_path() / "efdem_labels.data";
    write_lammps_data(path, test::random_particles(4, 4, 0.5, 3, 1), species, Domain{4, 4},
                      "labels");
    auto problem = [&](const SpeciesTable& other) {
        try {
            read_lammps_data(path, other, Domain{4, 4});
        } catch (const InputError& e) {
            CHECK(e.where().file == path.string());
            return e.problem();
        }
        return std::string("accepted");
    };
    // Same densities and diameters under other names: only the labels tell them apart.
    CHECK(problem(SpeciesTable({{"heavy", 1.0, 1.0}, {"light", 2.0, 1.0}})) ==
          "atom type 1 is labelled 'light', but the scene's species 1 is 'heavy' "
          "(species.names: type t is the t-th name)");
    CHECK(problem(SpeciesTable({{"light", 1.0, 1.0}, {"heavy", 2.0, 1.0}, {"third", 3.0, 1.0}})) ==
          "the file has 2 atom types (species), but species.names lists 3");
    CHECK(problem(species) == "accepted");
}

TEST_CASE("bed files per realization: _rNNNN before the extension", "[unit][io]") {
    CHECK(realization_file("runs/beds.data", 7) == std::filesystem::path("runs/beds_r0007.data"));
    CHECK(realization_file("beds.data.gz", 12) == std::filesystem::path("beds_r0012.data.gz"));
    CHECK(realization_file("/a/b.c/beds", 0) == std::filesystem::path("/a/b.c/beds_r0000"));
    CHECK(realization_file("beds.data", 12345) == std::filesystem::path("beds_r12345.data"));
}

TEST_CASE("a bed file that cannot be written is a runtime failure naming it", "[unit][io]") {
    const auto blocker = std::filesystem::temp_directory_path() / "efdem_not_a_folder";
    std::ofstream(blocker) << "x";
    const auto path = blocker / "beds.data";
    try {
        write_lammps_data(path, test::random_particles(2, 4, 0.5, 3, 1), test::binary_species(),
                          Domain{4, 4}, "t");
        FAIL("expected a RuntimeFailure");
    } catch (const RuntimeFailure& e) {
        CHECK(std::string(e.what()).find(path.string()) != std::string::npos);
    }
}
