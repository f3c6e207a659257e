// Scene -> effects wiring: "simulate only the effects a scene calls for". A scene builds only
// what its effects need; unknown effects, too-large time steps and keys for unlisted effects are
// input errors with clear messages.
#include <catch2/catch.hpp>

#include "core/error.hpp"
#include "dem/effect_registry.hpp"
#include "dem/realization_builder.hpp"
#include "dem/scene.hpp"
#include "tests/support/dem_fixtures.hpp"
#include "tests/support/input_error.hpp"

using namespace efdem;
using namespace efdem::dem;
using efdem::test::input_error;

namespace {
const std::string kBase = test::kSmallBinaryScene;

System build(ParamTable& t) {
    return build_system(t.root(), {1, 0});
}

}  // namespace

TEST_CASE("a frictionless scene allocates no contact history; no contact effect, no list",
          "[unit][effects]") {
    SECTION("tangential = none: neighbour list but no history") {
        auto t = test::scene_table(std::string(kBase) +
                                   "effects = gravity pair_contact wall_contact\n"
                                   "pair_contact.tangential = none\n");
        System s = build(t);
        CHECK(s.neighbor_list() != nullptr);
        CHECK(s.contact_history() == nullptr);
        CHECK_FALSE(s.needs().contact_history);
        CHECK(s.slab_fields() == nullptr);  // no effect reads slab fields
    }
    SECTION("tangential = history: history allocated") {
        auto t =
            test::scene_table(std::string(kBase) + "effects = gravity pair_contact wall_contact\n");
        System s = build(t);
        CHECK(s.contact_history() != nullptr);
    }
    SECTION("gravity alone: no neighbour list, no history") {
        auto t = test::scene_table(
            "dt = 1e-4\ndomain.lx = 4\ndomain.ly = 4\nspecies.names = a\nspecies.density = 1\n"
            "species.diameter = 1\nbed.count = 5\nbed.settle = false\neffects = gravity\n");
        System s = build(t);
        CHECK(s.neighbor_list() == nullptr);
        CHECK(s.contact_history() == nullptr);
        CHECK(s.effects().size() == 1);
    }
}

TEST_CASE("effects are applied in the listed order and each is built once", "[unit][effects]") {
    auto t =
        test::scene_table(std::string(kBase) + "effects = wall_contact gravity pair_contact\n");
    System s = build(t);
    REQUIRE(s.effects().size() == 3);
    CHECK(s.effects()[0]->name() == "wall_contact");
    CHECK(s.effects()[1]->name() == "gravity");
    CHECK(s.effects()[2]->name() == "pair_contact");
}

TEST_CASE("an unknown effect is an input error that lists the known effects", "[unit][effects]") {
    auto t = test::scene_table(std::string(kBase) + "effects = gravity pair_contatc\n");
    const auto e = input_error([&] { build(t); });
    CHECK(e.key() == "effects");
    CHECK(e.problem() == "names an unknown effect 'pair_contatc'");
    CHECK(e.allowed() == "known effects: " + effect_registry().names_joined());
    CHECK(e.where().line > 0);
}

TEST_CASE("keys of an effect that is not listed are reported with a hint", "[unit][effects]") {
    auto t = test::scene_table(std::string(kBase) + "effects = gravity\nwall_contact.kn = 1e5\n");
    System s = build(t);
    const auto e = input_error([&] {
        t.check_all_used(
            [&](const ParamEntry& entry) { return unused_key_hint(entry, {"gravity"}); });
    });
    // pair_contact.* comes first in the file.
    CHECK(e.key() == "pair_contact.kn");
    CHECK(e.problem().find("is 'pair_contact' listed in 'effects'?") != std::string::npos);
}

TEST_CASE("dt > t_c/5 is refused with the computed limit; t_c/20 < dt warns", "[unit][effects]") {
    // Shortest contact: light-light, t_c = 3.596e-3 (physics.md §5.2): limit 7.19e-4.
    SECTION("refused") {
        auto t =
            test::scene_table(std::string(kBase) + "effects = gravity pair_contact wall_contact\n");
        t.add_override("dt=8e-4");
        const auto e = input_error([&] { build(t); });
        INFO(e.what());
        CHECK(e.key() == "dt");
        CHECK(e.problem().find("exceeds t_c/5 = 0.0007193") != std::string::npos);
        CHECK(e.problem().find("light-light") != std::string::npos);
        CHECK(e.allowed().find("dt <= 0.0007193") != std::string::npos);
    }
    SECTION("warning band") {
        auto t =
            test::scene_table(std::string(kBase) + "effects = gravity pair_contact wall_contact\n");
        t.add_override("dt=3e-4");
        const DemScene scene = DemScene::from_params(t.root());
        const auto effects = make_effects(scene, t.root());
        const std::string w = check_time_step(scene, t.root(), effects);
        CHECK(w.find("t_c/12.0") != std::string::npos);
    }
    SECTION("stiff contacts scale the limit") {
        auto t =
            test::scene_table(std::string(kBase) + "effects = gravity pair_contact wall_contact\n");
        t.add_override("pair_contact.kn=2e7");  // t_c shrinks by 10: 3.596e-4
        const auto e = input_error([&] { build(t); });
        INFO(e.what());
        CHECK(e.problem().find("exceeds t_c/5 = 7.193e-05") != std::string::npos);
    }
}

TEST_CASE("wall_contact falls back to pair_contact's keys, and can override them",
          "[unit][effects]") {
    auto t = test::scene_table(std::string(kBase) +
                               "effects = gravity pair_contact wall_contact\n"
                               "wall_contact.restitution = 0.5\n");
    System s = build(t);
    const auto* wall = dynamic_cast<const WallContact*>(s.find_effect("wall_contact"));
    REQUIRE(wall != nullptr);
    CHECK(wall->table().spec().kn == 2e5);
    CHECK(wall->table().spec().restitution == 0.5);
    CHECK(wall->table().spec().mu == 0.1);
    CHECK_NOTHROW(t.check_all_used());
}

TEST_CASE("hertz with LAMMPS' single gamma_n is refused", "[unit][effects]") {
    auto t = test::scene_table(std::string(kBase) +
                               "effects = pair_contact\npair_contact.normal = hertz\n"
                               "pair_contact.damping = gamma\n");
    const auto e = input_error([&] { build(t); });
    CHECK(e.key() == "pair_contact.damping");
}

// Parameters by name: the coarse layer changes a scene key during a run (mode = continuation)
// without knowing which effect owns it; the registry row lists the key with the bounds the
// effect reads it with.
TEST_CASE("the registry lists the keys a run may change, with the bounds the scene reads them with",
          "[unit][effects]") {
    const std::vector<EffectParameter> all = run_parameters();
    REQUIRE(all.size() == 1);  // today only U_s; a new row shows up here
    CHECK(all[0].key == "gas_drag.superficial_velocity");
    CHECK(all[0].effect == "gas_drag");
    CHECK(all[0].parameter.bounds.describe() == "in [0, 1000]");
    CHECK(find_run_parameter("gas_drag.superficial_velocity").has_value());
    CHECK_FALSE(find_run_parameter("gas_drag.phi_cap").has_value());
    CHECK_FALSE(find_run_parameter("superficial_velocity").has_value());
    // The same bounds as the scene key: 1000 is accepted, 1000.5 refused with them (A = 1e-4
    // puts the terminal velocity rho/A, the scene's own limit, far above both).
    auto ok = test::scene_table(kBase +
                                "effects = gravity gas_drag\n"
                                "gas_drag.A = 1e-4\ngas_drag.superficial_velocity = 1000\n");
    CHECK_NOTHROW(build(ok));
    auto bad = test::scene_table(kBase +
                                 "effects = gravity gas_drag\n"
                                 "gas_drag.A = 1e-4\ngas_drag.superficial_velocity = 1000.5\n");
    const InputError e = input_error([&] { build(bad); });
    CHECK_THAT(e.what(), Catch::Contains("in [0, 1000]"));
}

TEST_CASE("System::set_parameter changes an effect's key by name, within its bounds",
          "[unit][effects]") {
    auto t = test::scene_table(kBase +
                               "effects = gravity pair_contact wall_contact gas_drag\n"
                               "gas_drag.A = 0.114939\ngas_drag.superficial_velocity = 0.19\n");
    System s = build(t);
    s.set_parameter("gas_drag.superficial_velocity", 0.41);
    CHECK(test::gas_effect(s).spec().superficial_velocity == 0.41);  // stored as given
    // Outside the key's bounds: a runtime failure naming the key, the value and the bounds; the
    // effect keeps its value.
    try {
        s.set_parameter("gas_drag.superficial_velocity", -0.01);
        FAIL("a negative U_s was accepted");
    } catch (const RuntimeFailure& f) {
        CHECK_THAT(f.what(), Catch::Contains("gas_drag.superficial_velocity = -0.01") &&
                                 Catch::Contains("outside [0, 1000]"));
    }
    CHECK(test::gas_effect(s).spec().superficial_velocity == 0.41);

    auto no_gas = test::scene_table(kBase + "effects = gravity pair_contact wall_contact\n");
    System dry = build(no_gas);
    try {
        dry.set_parameter("gas_drag.superficial_velocity", 0.3);
        FAIL("a scene without gas_drag accepted U_s");
    } catch (const RuntimeFailure& f) {
        CHECK_THAT(f.what(), Catch::Contains("does not list gas_drag"));
    }
}
