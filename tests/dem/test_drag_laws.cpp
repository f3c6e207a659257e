// The drag-law table and gas_drag's inputs: A from physical inputs (physics.md §3.3), U_mf
// (§6.1), and the input errors a chemical engineer may run into.
#include <catch2/catch.hpp>

#include <cmath>

#include "dem/gas/drag_laws.hpp"
#include "dem/gas/gas_drag.hpp"
#include "dem/realization_builder.hpp"
#include "tests/support/dem_fixtures.hpp"
#include "tests/support/input_error.hpp"

using namespace efdem;
using namespace efdem::dem;
using efdem::test::input_error;

namespace {
const char* kScene =
    "dt = 1e-4\n"
    "domain.lx = 4\ndomain.ly = 4\n"
    "species.names = light heavy\nspecies.density = 1 2\nspecies.diameter = 1 1\n"
    "bed.count = 5 5\nbed.settle = false\n"
    "effects = gravity gas_drag\n"
    "gas_drag.superficial_velocity = 0.41\n";

System build(ParamTable& t) {
    return build_system(t.root(), {1, 0});
}

const GasDrag& gas_of(const System& s) {
    const auto* g = dynamic_cast<const GasDrag*>(s.find_effect("gas_drag"));
    REQUIRE(g != nullptr);
    return *g;
}
}  // namespace

TEST_CASE("every drag law reduces to Stokes drag at phi = 0", "[unit][gas]") {
    for (const auto& law : kDragLaws) {
        INFO(law.name);
        CHECK(law.resistance(0.0) == 1.0);
        CHECK(law.resistance(0.3) > 1.0);  // a denser suspension resists more
    }
    // Wen & Yu, low Re: (1 - phi)^-2.65.
    CHECK(wen_yu_low_re_resistance(0.6) == Approx(std::pow(0.4, -2.65)).epsilon(1e-15));
    CHECK(find_drag_law("wen_yu_low_re") == &kDragLaws[0]);
    CHECK(find_drag_law("ergun") == nullptr);
}

TEST_CASE("an unknown drag law is an input error that lists the known ones", "[unit][gas]") {
    auto t = test::scene_table(std::string(kScene) + "gas_drag.law = stokes\n");
    const auto e = input_error([&] { build(t); });
    CHECK(e.key() == "gas_drag.law");
    CHECK(e.value() == "stokes");
    CHECK(e.where().line == 11);
    CHECK(e.problem() == "names an unknown drag law 'stokes'");
    CHECK(e.allowed() == "known drag laws: wen_yu_low_re");
}

TEST_CASE("A from the physical defaults is 0.114939 (physics.md §3.3)", "[unit][gas]") {
    CHECK(GasProperties{}.drag_number() == Approx(0.114939).margin(5e-7));
    // A = 18 mu_g/(rho_s d_p^1.5 g^0.5): linear in mu_g, inverse in rho_s.
    CHECK(GasProperties{.viscosity = 3.6e-5}.drag_number() == Approx(2 * 0.114939).margin(1e-6));
    CHECK(GasProperties{.particle_density = 1800}.drag_number() ==
          Approx(0.114939 / 2).margin(1e-6));
    // Units of the Fig. 1 parameters: 3.193 ms and 3.132 cm/s (physics.md §2).
    CHECK(GasProperties{}.time_unit() == Approx(3.193e-3).epsilon(1e-3));
    CHECK(GasProperties{}.velocity_unit() == Approx(3.132e-2).epsilon(1e-3));

    auto t = test::scene_table(kScene);
    System s = build(t);
    const GasDragSpec& spec = gas_of(s).spec();
    CHECK(spec.A == Approx(0.114939).margin(5e-7));
    CHECK(spec.physical);
    CHECK(spec.phi_cap == 0.70);
    CHECK(spec.slab_thickness == 1.0);
    CHECK(spec.superficial_velocity == 0.41);
    CHECK_NOTHROW(t.check_all_used());
    // The defaults are recorded, so that the run log is a complete record.
    bool logged = false;
    for (const auto& r : t.resolved())
        logged |= r.key == "gas_drag.gas_viscosity" && r.origin == "default";
    CHECK(logged);
}

TEST_CASE("A is given directly or derived, never both", "[unit][gas]") {
    SECTION("given") {
        auto t = test::scene_table(std::string(kScene) + "gas_drag.A = 0.2\n");
        System s = build(t);
        CHECK(gas_of(s).spec().A == 0.2);
        CHECK_FALSE(gas_of(s).spec().physical);
    }
    SECTION("both") {
        auto t = test::scene_table(std::string(kScene) +
                                   "gas_drag.A = 0.2\ngas_drag.gas_viscosity = 2e-5\n");
        const auto e = input_error([&] { build(t); });
        CHECK(e.key() == "gas_drag.gas_viscosity");
        CHECK(e.problem().find("together with gas_drag.A") != std::string::npos);
        CHECK(e.allowed().find("either gas_drag.A alone") != std::string::npos);
    }
    SECTION("physical, not the defaults") {
        auto t = test::scene_table(std::string(kScene) + "gas_drag.gas_viscosity = 3.6e-5\n");
        System s = build(t);
        CHECK(gas_of(s).spec().A == Approx(2 * 0.114939).margin(1e-6));
    }
    SECTION("A must be positive") {
        auto t = test::scene_table(std::string(kScene) + "gas_drag.A = 0\n");
        CHECK(input_error([&] { build(t); }).key() == "gas_drag.A");
    }
}

TEST_CASE("gas_drag's other inputs are checked", "[unit][gas]") {
    SECTION("U_s is required") {
        auto t = test::scene_table(
            "dt = 1e-4\ndomain.lx = 4\ndomain.ly = 4\nspecies.names = a\nspecies.density = 1\n"
            "species.diameter = 1\nbed.count = 5\nbed.settle = false\neffects = gas_drag\n");
        const auto e = input_error([&] { build(t); });
        CHECK(e.key() == "gas_drag.superficial_velocity");
        CHECK(e.problem().find("required") != std::string::npos);
    }
    SECTION("the cap lies in (0, 1)") {
        auto t = test::scene_table(std::string(kScene) + "gas_drag.phi_cap = 1\n");
        CHECK(input_error([&] { build(t); }).key() == "gas_drag.phi_cap");
    }
    SECTION("U_s at most the terminal velocity of the heaviest species, rho_max / A") {
        // A = 0.114939, rho_max = 2: 17.40 (physics.md §3.3); 17.5 blows every sphere to the lid.
        auto ok = test::scene_table(std::string(kScene));
        ok.add_override("gas_drag.superficial_velocity=17.4");
        CHECK_NOTHROW(build(ok));
        auto t = test::scene_table(std::string(kScene));
        t.add_override("gas_drag.superficial_velocity=17.5");
        const auto e = input_error([&] { build(t); });
        CHECK(e.key() == "gas_drag.superficial_velocity");
        CHECK_THAT(e.problem(), Catch::Contains("terminal velocity rho d^2/A = 17.4"));
        CHECK_THAT(e.allowed(), Catch::Contains("[0, 17.4"));
    }
    SECTION("slabs from 0.1 to 10 d_p, two of them below the lid") {
        auto t = test::scene_table(std::string(kScene) + "gas_drag.slab_thickness = 1e300\n");
        CHECK_THAT(input_error([&] { build(t); }).allowed(), Catch::Contains("[0.1, 10]"));
        auto lid = test::scene_table(std::string(kScene) +
                                     "domain.lid = 12\ngas_drag.slab_thickness = 7\n");
        const auto e = input_error([&] { build(lid); });
        CHECK(e.key() == "gas_drag.slab_thickness");
        CHECK_THAT(e.allowed(), Catch::Contains("[0.1, 6]"));
    }
    SECTION("dt within the drag relaxation time tau = rho_min (1 - phi_cap)^2.65 / A") {
        // tau = 0.3^2.65 / A = 0.04115 / A: at dt = 1e-4, A = 411.5 is the limit. Measured on the
        // tiny test bed: A = 1000 (dt = 2.4 tau) runs, A = 1500 (3.7 tau) leaves the box.
        // (U_s = 0: at such an A the gas would otherwise blow the bed away, refused first.)
        auto ok = test::scene_table(std::string(kScene) + "gas_drag.A = 400\n");
        ok.add_override("gas_drag.superficial_velocity=0");
        CHECK_NOTHROW(build(ok));
        auto t = test::scene_table(std::string(kScene) + "gas_drag.A = 3000\n");
        t.add_override("gas_drag.superficial_velocity=0");
        const auto e = input_error([&] { build(t); });
        CHECK(e.key() == "dt");
        CHECK_THAT(e.problem(), Catch::Contains("drag relaxation time tau"));
        CHECK_THAT(e.problem(), Catch::Contains("gas_drag.A = 3000"));
        CHECK_THAT(e.allowed(), Catch::Contains("dt <= 1.372e-05, or gas_drag.A <= 411.5"));
    }
    SECTION("one particle size") {
        auto t = test::scene_table(std::string(kScene));
        t.add_override("species.diameter=1 1.5");
        const auto e = input_error([&] { build(t); });
        CHECK(e.key() == "species.diameter");
        CHECK(e.problem().find("gas_drag") != std::string::npos);
        CHECK_THAT(e.allowed(), Catch::Contains("gas_drag.polydisperse = van_der_hoef"));
    }
    SECTION("several sizes: the polydisperse closure, within its ratio of 4") {
        auto t = test::scene_table(std::string(kScene) + "gas_drag.polydisperse = van_der_hoef\n");
        t.add_override("species.diameter=1 1.5");
        CHECK(gas_of(build(t)).spec().polydisperse);
        auto wide =
            test::scene_table(std::string(kScene) + "gas_drag.polydisperse = van_der_hoef\n");
        wide.add_override("species.diameter=0.4 2");
        wide.add_override("domain.lx=8");
        wide.add_override("domain.ly=8");
        const auto e = input_error([&] { build(wide); });
        CHECK(e.key() == "species.diameter");
        CHECK(e.value() == "0.4 2");
        CHECK_THAT(e.problem(), Catch::Contains("ratio of 5"));
        CHECK_THAT(e.allowed(), Catch::Contains("ratio of 4"));
        auto unknown =
            test::scene_table(std::string(kScene) + "gas_drag.polydisperse = beetstra\n");
        const auto u = input_error([&] { build(unknown); });
        CHECK(u.key() == "gas_drag.polydisperse");
        CHECK(u.where().line == 11);
        CHECK_THAT(u.allowed(), Catch::Contains("van_der_hoef"));
    }
}

TEST_CASE("U_mf and the Stokes numbers match physics.md §6.1 and §12.3", "[unit][gas]") {
    auto t = test::scene_table(kScene);
    System s = build(t);
    const GasDrag& gas = gas_of(s);
    // §6.1 table (4 significant digits): light, heavy at phi = 0.60 and 0.612.
    CHECK(gas.minimum_fluidization_velocity(1, 0.60) == Approx(0.1228).margin(5e-5));
    CHECK(gas.minimum_fluidization_velocity(2, 0.60) == Approx(0.2456).margin(5e-5));
    CHECK(gas.minimum_fluidization_velocity(1, 0.612) == Approx(0.1066).margin(5e-5));
    CHECK(gas.minimum_fluidization_velocity(1.5, 0.612) == Approx(0.1598).margin(5e-5));
    EffectReport r;
    gas.describe(r);
    std::string text;
    for (const auto& [k, v] : r.lines) text += k + ": " + v + "\n";
    INFO(text);
    CHECK(text.find("A: 0.114939") != std::string::npos);
    CHECK(text.find("species light: Stokes terminal velocity and relaxation time 8.7") !=
          std::string::npos);
    CHECK(text.find("species heavy: Stokes terminal velocity and relaxation time 17.4") !=
          std::string::npos);
    CHECK(text.find("U_mf at phi = 0.6: 0.1228") != std::string::npos);
    CHECK(text.find("1.284 cm/s") != std::string::npos);  // U_s = 0.41 (physics.md §2)
    // 0.41 is above both U_mf (0.1228, 0.2456); 0.19 lies between them.
    CHECK(text.find("fluidization: U_s = 0.41 is above every species' U_mf") != std::string::npos);
    auto t_slow = test::scene_table(kScene);
    t_slow.add_override("gas_drag.superficial_velocity=0.19");
    System s_slow = build(t_slow);
    EffectReport slow;
    gas_of(s_slow).describe(slow);
    std::string slow_text;
    for (const auto& [k, v] : slow.lines) slow_text += k + ": " + v + "\n";
    INFO(slow_text);
    CHECK(slow_text.find("fluidization: U_s = 0.19 fluidizes light but not heavy on its own") !=
          std::string::npos);
}
