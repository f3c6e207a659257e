// bed.read: a realization started from the bed an earlier run kept (dem::write_lammps_data, as
// bed.write does) is the realization that run started, bit for bit; a bed that does not fit the
// scene is refused naming bed.read; a shared bed with bed.read.velocity_rms gives each
// realization its own start.
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "dem/io/lammps_data.hpp"
#include "dem/realization_builder.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {
// 40 spheres settled quickly: settled enough for a bed to keep (a test of the round trip, not of
// settling).
const std::string kScene = test::kSmallBinaryScene +
                           "effects = gravity pair_contact wall_contact\n"
                           "bed.settle.ke_threshold = 1e-3\nbed.settle.max_time = 20\n";

ParamTable table(const std::vector<std::string>& overrides) {
    auto t = test::scene_table(kScene);
    t.add_override("bed.settle=true");
    for (const auto& o : overrides) t.add_override(o);
    return t;
}

const std::filesystem::path kName = std::filesystem::temp_directory_path() / "efdem_beds.data";

/// Builds realization r of kScene (settled, seed 3) and keeps its bed as bed.write does.
System build_and_write(long r, const std::vector<std::string>& overrides = {}) {
    auto t = table(overrides);
    const Params root = t.root();
    Particles built;
    System s = build_system(root, {3, r, false}, {}, &built);
    write_lammps_data(realization_file(kName, r), built, s.species(), s.domain(), "test");
    return s;
}

void require_same(const System& a, const System& b) {
    const Particles &p = a.particles(), &q = b.particles();
    REQUIRE(p.size() == q.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
        INFO("particle " << i);
        REQUIRE(p.tag()[i] == q.tag()[i]);
        REQUIRE(p.species()[i] == q.species()[i]);
        REQUIRE(p.x()[i].x == q.x()[i].x);
        REQUIRE(p.x()[i].y == q.x()[i].y);
        REQUIRE(p.x()[i].z == q.x()[i].z);
        REQUIRE(p.v()[i].x == q.v()[i].x);
        REQUIRE(p.v()[i].z == q.v()[i].z);
        REQUIRE(p.omega()[i].y == q.omega()[i].y);
    }
}

InputError refusal(const std::vector<std::string>& overrides, long r = 0) {
    auto t = table(overrides);
    try {
        build_system(t.root(), {3, r, false});
    } catch (const InputError& e) {
        return e;
    }
    FAIL("expected an InputError");
    throw std::logic_error("unreachable");
}
}  // namespace

TEST_CASE("a run from a kept bed starts, and runs, exactly as the run that settled it",
          "[unit][bed]") {
    for (const bool permute : {false, true}) {
        INFO("bed.permute_species = " << permute);
        const std::string perm = fmt::format("bed.permute_species={}", permute);
        System settled = build_and_write(1, {perm});
        auto t = table({perm, "bed.read=" + kName.string()});
        System reused = build_system(t.root(), {3, 1, false});
        require_same(settled, reused);
        // The first 2000 steps too: forces, neighbour lists and contact history start alike.
        settled.run(2000);
        reused.run(2000);
        require_same(settled, reused);
    }
}

TEST_CASE("a kept bed that does not fit the scene is refused, naming bed.read or the file",
          "[unit][bed]") {
    build_and_write(0);
    const std::string read = "bed.read=" + kName.string();
    SECTION("no file for this realization") {
        const auto e = refusal({read}, 5);
        CHECK(e.key() == "bed.read");
        CHECK(e.problem() == "has no bed for realization 5: " +
                                 realization_file(kName, 5).string() + " does not exist");
    }
    SECTION("a shared file that does not exist") {
        const auto e = refusal({"bed.read=/nonexistent/beds.data", "bed.read.shared=true"});
        CHECK(e.key() == "bed.read");
        CHECK(e.problem() == "names no file (/nonexistent/beds.data does not exist)");
    }
    SECTION("other particle counts") {
        const auto e = refusal({read, "bed.count=21 19"});
        CHECK(e.key() == "bed.read");
        CHECK(e.problem() == realization_file(kName, 0).string() +
                                 " holds 20 light, 20 heavy, but bed.count = 21 19");
    }
    SECTION("another box") {
        const auto e = refusal({read, "domain.lx=4.5"});
        CHECK(e.where().file == realization_file(kName, 0).string());
        CHECK(e.problem().find("domain.lx = 4.5") != std::string::npos);
    }
    SECTION("another species") {
        const auto e = refusal({read, "species.density=1 3"});
        CHECK(e.where().file == realization_file(kName, 0).string());
        CHECK(e.problem().find("species 'heavy' has diameter 1 and density 3") !=
              std::string::npos);
    }
    SECTION("bed.read.* without bed.read, bed.read with a data-file bed") {
        CHECK(refusal({"bed.read.velocity_rms=0.1"}).key() == "bed.read.velocity_rms");
        CHECK(refusal({read, "bed.source=lammps_data", "bed.file=x.data"}).key() == "bed.read");
    }
    SECTION("a restart, whose bed the checkpoint overwrites, does not need the file") {
        auto t = table({"bed.read=/nonexistent/beds.data"});
        CHECK_NOTHROW(build_system(t.root(), {3, 0, true, true}));
    }
}

TEST_CASE("a shared bed with bed.read.velocity_rms: each realization its own, valid start",
          "[unit][bed]") {
    build_and_write(0);
    const std::vector<std::string> shared = {"bed.read=" + realization_file(kName, 0).string(),
                                             "bed.read.shared=true", "bed.read.velocity_rms=0.05"};
    auto t = table(shared);
    std::vector<System> systems;
    for (long r = 0; r < 3; ++r) systems.push_back(build_system(t.root(), {3, r, false}));
    // The same positions, other velocities (rms 0.05: a tenth of a fluidized bed's agitation).
    CHECK(systems[0].particles().x()[5].z == systems[1].particles().x()[5].z);
    CHECK(systems[0].particles().v()[5].x != systems[1].particles().v()[5].x);
    double sum_v2 = 0;
    for (const Vec3& v : systems[2].particles().v()) sum_v2 += dot(v, v);
    // The settled bed is at rest (settling ends so), so this is the added noise alone: 40 spheres
    // x 3 components, the mean square speed within 50 % of 0.05^2 (chi-square with 120 degrees
    // of freedom: relative sigma 13 %, so ~4 sigma).
    CHECK(sum_v2 / 40 == Approx(0.0025).epsilon(0.5));
    for (auto& s : systems) {
        s.run(5000);
        CHECK(!s.health_problem());
        CHECK(s.thermo_stats().max_overlap < 0.1);  // the watchdog's default limit
    }
    // Half a time unit later the beds differ.
    CHECK(systems[0].particles().x()[5].z != systems[1].particles().x()[5].z);
}
