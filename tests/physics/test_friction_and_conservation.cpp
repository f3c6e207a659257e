// Oblique impacts with Coulomb friction, free fall, rest on the floor, momentum and energy
// balances (the DEM-01..06 style checks of landscape.md §4).
#include <catch2/catch.hpp>

#include <cmath>

#include "core/rng.hpp"
#include "dem/body_forces/gravity.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::dem;
using efdem::test::binary_species;
using efdem::test::paper_contact;

namespace {
struct Impulses {
    double normal, tangential, omega_y;
    double normal_abs;  ///< integral of |F_n| dt: the Coulomb bound is mu times this
};

/// A light sphere hits the floor with velocity (vt, 0, -vn) and no spin, no gravity. Returns the
/// impulses the floor gave it (from its change of momentum) and its final spin.
Impulses oblique_floor_impact(double vt, double vn) {
    const SpeciesTable species = binary_species();
    Particles p;
    p.add(1, {5, 5, 0.505}, {vt, 0, -vn}, 0, species);
    test::EffectList fx;
    fx.wall(paper_contact(), species);
    System sys = test::make_system(species, {10, 10}, std::move(p), std::move(fx), 2e-6);
    const double m = species.mass(0);
    double normal_abs = 0;
    // Velocity Verlet changes the momentum by dt F_k per evaluated force F_k (the two half
    // kicks of consecutive steps add up), and the first and last evaluations are out of contact,
    // so the normal impulse bound is exactly sum_k dt |F_n,k|.
    while (sys.particles().x()[0].z < 0.6 && sys.time() < 1.0) {
        sys.step();
        normal_abs += sys.dt() * std::abs(sys.particles().force()[0].z);
    }
    const Vec3 v = sys.particles().v()[0];
    return {m * (v.z + vn), m * (v.x - vt), sys.particles().omega()[0].y, normal_abs};
}
}  // namespace

TEST_CASE("oblique impact: sliding uses the full Coulomb limit, sticking stays inside it",
          "[physics][contact][friction]") {
    const double mu = 0.1, r = 0.5, inertia = binary_species().inertia(0);
    SECTION("sliding: large tangential speed") {
        const Impulses j = oblique_floor_impact(2.0, 1.0);
        // The limit is mu |F_n| with F_n including damping (LAMMPS convention); F_n turns
        // slightly attractive at the end of an unclamped contact, so the bound on the tangential
        // impulse is mu times the integral of |F_n|, not mu J_n.
        CHECK(std::abs(j.tangential) <= mu * j.normal_abs * (1 + 1e-9));
        // The contact slides throughout, so J_t = mu J_n up to that attractive tail and the first
        // steps where the spring has not reached the limit: within 1 %.
        CHECK(std::abs(j.tangential) == Approx(mu * j.normal).epsilon(0.01));
        CHECK(j.tangential < 0);  // friction opposes the sliding direction (+x)
        // Spin from the torque of the tangential impulse: I w = r |J_t|, and positive about y
        // for motion along +x on a floor below.
        CHECK(j.omega_y > 0);
        CHECK(inertia * j.omega_y == Approx(r * std::abs(j.tangential)).epsilon(1e-6));
    }
    SECTION("sticking: small tangential speed") {
        const Impulses j = oblique_floor_impact(0.01, 1.0);
        CHECK(std::abs(j.tangential) < 0.9 * mu * j.normal);
        CHECK(j.omega_y > 0);
        CHECK(inertia * j.omega_y == Approx(r * std::abs(j.tangential)).epsilon(1e-6));
    }
}

TEST_CASE("free fall is exact and a sphere comes to rest on the floor", "[physics][gravity]") {
    const SpeciesTable species = binary_species();
    SECTION("free fall: z(t) = z0 - t^2/2 (velocity Verlet is exact for a constant force)") {
        Particles p;
        p.add(1, {1, 1, 100}, {}, 0, species);
        test::EffectList fx;
        fx.gravity();
        System sys = test::make_system(species, {10, 10}, std::move(p), std::move(fx), 1e-3);
        sys.run(2000);
        const double t = sys.time();
        // Round-off of 2000 additions of O(1) terms: 1e-11 absolute is generous.
        CHECK(sys.particles().x()[0].z == Approx(100 - 0.5 * t * t).margin(1e-9));
        CHECK(sys.particles().v()[0].z == Approx(-t).margin(1e-11));
    }
    SECTION("rest on the floor at the static overlap m g / kn") {
        Particles p;
        p.add(1, {1, 1, 0.6}, {}, 1, species);  // heavy
        test::EffectList fx;
        fx.gravity().wall(paper_contact(), species);
        System sys = test::make_system(species, {10, 10}, std::move(p), std::move(fx), 1e-4);
        sys.run(100000);
        const double m = species.mass(1);
        // Damped oscillation (eta_n = 30.7, m = 1.05: decay time 0.07) is gone after 10 units.
        CHECK(sys.particles().x()[0].z == Approx(0.5 - m / 2e5).margin(1e-9));
        CHECK(std::abs(sys.particles().v()[0].z) < 1e-9);
    }
}

namespace {
/// A random dilute gas of light and heavy spheres with random velocities and spins, in a
/// periodic box without floor contact (z only bounded by nothing: the gas is given no vertical
/// drift); pair_contact with friction.
System random_gas(const ContactSpec& spec, int n, double l, bool walls, double lid = 0) {
    const SpeciesTable species = binary_species();
    RandomStream rng(9, 0, "test");
    Particles p;
    while (static_cast<int>(p.size()) < n) {
        const Vec3 x{rng.uniform(0, l), rng.uniform(0, l), rng.uniform(1, l - 1)};
        bool free = true;
        for (const auto& y : p.x()) free &= norm2(Domain{l, l}.minimum_image(x - y)) > 1.05 * 1.05;
        if (!free) continue;
        p.add(static_cast<Tag>(p.size() + 1), x, {rng.normal(), rng.normal(), rng.normal()},
              static_cast<SpeciesId>(rng.below(2)), species);
        p.omega()[p.size() - 1] = {rng.normal(), rng.normal(), rng.normal()};
    }
    test::EffectList fx;
    fx.pair(spec, species);
    if (walls) fx.wall(spec, species);
    Domain d{l, l};
    if (lid > 0) d.lid_height = lid;
    return test::make_system(species, d, std::move(p), std::move(fx), 1e-4);
}

Vec3 momentum(const System& s) {
    Vec3 m{};
    for (std::size_t i = 0; i < s.particles().size(); ++i)
        m += s.particles().v()[i] * s.particles().mass()[i];
    return m;
}
}  // namespace

TEST_CASE("total momentum is conserved to round-off in a periodic box without walls",
          "[physics][conservation]") {
    System sys = random_gas(paper_contact(), 200, 8.0, false);
    const Vec3 p0 = momentum(sys);
    long contacts_seen = 0;
    for (int k = 0; k < 20; ++k) {
        sys.run(100);
        contacts_seen += sys.thermo_stats().contacts;
    }
    REQUIRE(contacts_seen > 0);  // the test means something only if collisions happened
    const Vec3 p1 = momentum(sys);
    // Pair forces are applied as exact opposites; the sum changes only by round-off, about
    // 1e-16 per addition times ~1e5 contact updates: 1e-10 absolute (|p| ~ 10).
    CHECK(std::abs(p1.x - p0.x) < 1e-10);
    CHECK(std::abs(p1.y - p0.y) < 1e-10);
    CHECK(std::abs(p1.z - p0.z) < 1e-10);
}

TEST_CASE("kinetic + elastic energy never increases in a closed box", "[physics][conservation]") {
    // Closed box: periodic sides, floor and lid, no gravity. Collisions dissipate; the velocity
    // Verlet error of a resolved contact (dt = t_c/36) is O((dt/t_c)^2) ~ 1e-3 of the energy in
    // the contacts at that moment, far smaller than the loss of one collision with e = 0.9.
    System sys = random_gas(paper_contact(), 150, 8.0, true, 8.0);
    double previous = sys.kinetic_energy() + sys.potential_energy();
    const double e0 = previous;
    for (int k = 0; k < 100; ++k) {
        sys.run(50);
        const double e = sys.kinetic_energy() + sys.potential_energy();
        INFO("sample " << k);
        CHECK(e <= previous + 1e-4 * e0);
        previous = e;
    }
    CHECK(previous < 0.99 * e0);  // and collisions did dissipate
}
