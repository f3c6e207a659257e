// gas_drag against closed-form physics (physics.md §3, §4, §6): Stokes settling of an isolated
// particle, the exact momentum identity of the conservative scheme, the phi cap, and a force
// that stays finite and continuous in every corner (one particle, empty slabs, ejected particles).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "dem/beds/bed_diagnostics.hpp"
#include "dem/gas/slab_fields.hpp"
#include "dem/realization_builder.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {
constexpr double kSphere = std::numbers::pi / 6.0;
const double kA = GasProperties{}.drag_number();

System gas_only(Particles p, const Domain& d, const GasDragSpec& spec, bool gravity = false,
                double dt = 1e-4) {
    const auto species = test::binary_species();
    test::EffectList fx;
    if (gravity) fx.gravity();
    fx.gas(spec, species);
    return test::make_system(species, d, std::move(p), std::move(fx), dt);
}

Vec3 total_force(const System& s) {
    Vec3 f{};
    for (const auto& fi : s.particles().force()) f += fi;
    return f;
}
}  // namespace

TEST_CASE("an isolated particle relaxes to Stokes settling U_s - rho/A with time rho/A",
          "[physics][gas]") {
    // Exact solution with v(0) = 0: v(t) = v_inf (1 - exp(-t/tau)), v_inf = U_s - tau, tau =
    // (rho_i/rho_s)/A = 8.70 (light), 17.40 (heavy) (physics.md §6.4).
    // Tolerance 2e-3 relative (tighter than the 1 % asked for, so that a 1 % error in A or in the
    // hindrance fails): the only deviations are the hindrance of the particle's own solid
    // fraction, (1 - phi)^-4.65 - 1 < 6e-5 in a 200 x 200 box, and the integrator, whose
    // half-step drag decays by (1 - dt/tau) per step: tau off by about dt/(2 tau) < 3e-4 at
    // dt = 5e-3 (no contacts, so dt only has to resolve tau). Measured: velocity history within
    // 9e-5 of the exponential, fitted tau within 5e-4.
    const double u = 0.41, dt = 5e-3;
    for (int s = 0; s < 2; ++s) {
        const double rho = s == 0 ? 1.0 : 2.0;
        const double tau = rho / kA, v_inf = u - tau;
        INFO("species " << s << ": tau = " << tau);
        Particles p;
        const double z0 = 12 * tau * tau;  // it falls about 10 tau * tau before the end
        p.add(1, {100, 100, z0}, {}, static_cast<SpeciesId>(s), test::binary_species());
        System sys = gas_only(std::move(p), Domain{200, 200}, test::paper_gas(u), true, dt);
        std::vector<double> t, v;
        double max_dev = 0;
        const long every = static_cast<long>(std::lround(0.25 * tau / dt));
        for (int k = 0; k < 40; ++k) {  // 10 tau
            sys.run(every);
            const double vz = sys.particles().v()[0].z;
            t.push_back(sys.time());
            v.push_back(vz);
            max_dev = std::max(max_dev, std::abs(vz - v_inf * (1 - std::exp(-sys.time() / tau))));
        }
        CHECK(max_dev < 2e-3 * std::abs(v_inf));
        // Terminal velocity: the last value (exp(-10) = 4.5e-5 of the way left).
        CHECK(v.back() == Approx(v_inf).epsilon(2e-3));
        // Time constant: least-squares slope of ln(1 - v/v_end) over the first 2 tau (later
        // points would amplify the 1e-4 error of v_end as a stand-in for v_inf by e^(t/tau)).
        double st = 0, sy = 0, stt = 0, sty = 0;
        int n = 0;
        for (std::size_t k = 0; k < t.size() && t[k] <= 2 * tau + 1e-9; ++k, ++n) {
            const double y = std::log(1 - v[k] / v.back());
            st += t[k], sy += y, stt += t[k] * t[k], sty += t[k] * y;
        }
        const double slope = (n * sty - st * sy) / (n * stt - st * st);
        CHECK(-1.0 / slope == Approx(tau).epsilon(2e-3));
    }
}

TEST_CASE("total gas force = area x sum_j dz (-grad p)_j, to round-off", "[physics][gas]") {
    // physics.md §4 item 4 and §6.3: the partial-volume form is exactly conservative because
    // sum_i V_ij (u_s,j - v_i) = 0 in every slab. Random positions and velocities; particles cut
    // by slab boundaries and by the floor (z from -0.3); a cluster above the cap (phi > 0.7).
    // Round-off: sums of ~1e3 terms of size |F_i|, so 1e-12 of sum |F_i|.
    const double l = 6;
    for (double dz : {0.5, 1.0, 2.0})
        for (double u : {0.0, 0.19, 0.41}) {
            INFO("dz = " << dz << ", U_s = " << u);
            Particles p = test::random_particles(300, l, -0.3, 12, 11);
            const Particles cluster = test::random_particles(80, l, 13.0, 13.4, 12);
            const auto species = test::binary_species();
            for (std::size_t i = 0; i < cluster.size(); ++i)
                p.add(1000 + static_cast<Tag>(i), cluster.x()[i], cluster.v()[i],
                      cluster.species()[i], species);
            System sys = gas_only(std::move(p), Domain{l, l}, test::paper_gas(u, dz));
            const SlabFields& slabs = *sys.slab_fields();
            double phi_max = 0;
            for (double phi : slabs.phi()) phi_max = std::max(phi_max, phi);
            if (dz <= 1.0) CHECK(phi_max > 0.7);  // the cap is exercised
            const auto* gas = dynamic_cast<const GasDrag*>(sys.find_effect("gas_drag"));
            std::vector<Vec3> grad(slabs.size());
            gas->pressure_gradient(slabs, sys.particles(), grad);
            Vec3 expected{};
            for (const auto& g : grad) expected += g * (l * l * dz);
            const Vec3 f = total_force(sys);
            double scale = 0;
            for (const auto& fi : sys.particles().force()) scale += norm(fi);
            CHECK(std::abs(f.x - expected.x) < 1e-12 * scale);
            CHECK(std::abs(f.y - expected.y) < 1e-12 * scale);
            CHECK(std::abs(f.z - expected.z) < 1e-12 * scale);
            CHECK(std::abs(pressure_drop(sys) - f.z / (l * l)) < 1e-12 * scale);
        }
}

TEST_CASE("the phi cap replaces phi inside every (1-phi) factor", "[physics][gas]") {
    // Two spheres on top of each other in a 1 x 1 box: phi_0 = 2 pi/6 = 1.047, beyond the cap
    // (and beyond 1). Expected force on each: V c [(u_s - v_i) - (u_s - U_s)/(1-0.7)^2] with
    // c = A (0.3)^-2.65 and u_s the mean velocity; finite, to round-off.
    const auto species = test::binary_species();
    Particles p;
    p.add(1, {0.5, 0.5, 0.5}, {0, 0, 0.2}, 0, species);
    p.add(2, {0.5, 0.5, 0.5}, {0.1, 0, -0.3}, 1, species);
    const double u = 0.41;
    System sys = gas_only(p, Domain{1, 1}, test::paper_gas(u));
    REQUIRE(sys.slab_fields()->phi()[0] == Approx(2 * kSphere));
    const double c = kA * std::pow(0.3, -2.65);
    const Vec3 u_s = (p.v()[0] + p.v()[1]) * 0.5;
    const Vec3 g = (u_s - Vec3{0, 0, u}) * (1 / 0.09);
    for (int i = 0; i < 2; ++i) {
        const Vec3 expected = (u_s - p.v()[i] - g) * (kSphere * c);
        const Vec3 f = sys.particles().force()[i];
        CHECK(f.x == Approx(expected.x).epsilon(1e-13));
        CHECK(f.z == Approx(expected.z).epsilon(1e-13));
    }
    // A cap above phi changes nothing; the same state with cap 0.95 gives larger forces.
    GasDragSpec loose = test::paper_gas(u);
    loose.phi_cap = 0.95;
    System sys2 = gas_only(p, Domain{1, 1}, loose);
    CHECK(std::abs(sys2.particles().force()[0].z) > 10 * std::abs(sys.particles().force()[0].z));
}

TEST_CASE("the gas force is continuous as a particle crosses slab boundaries and leaves the bed",
          "[physics][gas]") {
    // A probe moves up in steps of h = 1e-3 from inside a dense layer (phi ~ 0.6) through slab
    // boundaries into empty slabs above. Partial volumes are C1 in z, so the force changes by
    // O(h |dF/dz|) per step; a centre-binning scheme would jump by O(|F|) at each boundary. The
    // bound 1 % of max |F| per step sits between the two (smooth: ~0.1-0.3 %).
    const double l = 4;
    Particles p = test::random_particles(90, l, 0.5, 3.5, 5);
    p.add(999, {1, 1, 2.0}, {0.1, 0, -0.5}, 0, test::binary_species());
    System sys = gas_only(std::move(p), Domain{l, l}, test::paper_gas(0.41));
    const std::size_t probe = sys.particles().size() - 1;
    Vec3 last_probe{}, last_total{};
    double jump_probe = 0, jump_total = 0, max_probe = 0, max_total = 0;
    for (int k = 0; k <= 4000; ++k) {
        sys.particles().x()[probe].z = 2.0 + 1e-3 * k;
        sys.refresh_forces();
        const Vec3 f = sys.particles().force()[probe], tot = total_force(sys);
        REQUIRE(all_finite(f));
        if (k > 0) {
            jump_probe = std::max(jump_probe, norm(f - last_probe));
            jump_total = std::max(jump_total, norm(tot - last_total));
        }
        max_probe = std::max(max_probe, norm(f));
        max_total = std::max(max_total, norm(tot));
        last_probe = f;
        last_total = tot;
    }
    CHECK(jump_probe < 0.01 * max_probe);
    CHECK(jump_total < 0.01 * max_total);
    // At z = 6 the probe is alone in its slabs (u_s = v there): Stokes drag toward U_s,
    // hindered only by its own phi: F = sum_k V_k A (1-phi_k)^-4.65 (U_s - v), to round-off.
    const SlabFields& s = *sys.slab_fields();
    Vec3 expected{};
    for (int k = 0; k < s.slab_count(probe); ++k) {
        const double phi = s.phi()[s.first_slab(probe) + static_cast<std::uint32_t>(k)];
        expected +=
            Vec3{-0.1, 0, 0.41 + 0.5} * (s.weights(probe)[k] * kA * std::pow(1 - phi, -4.65));
    }
    CHECK(last_probe.x == Approx(expected.x).epsilon(1e-12));
    CHECK(last_probe.z == Approx(expected.z).epsilon(1e-12));
}

TEST_CASE("a particle ejected far above the bed feels Stokes drag and nothing breaks",
          "[physics][gas]") {
    // issue 10 item 3: particles far above the bed. One sphere at z = 5000.3 over a dense bed in
    // a 15 x 15 box: its slabs hold only itself (phi = pi/6/225 = 0.0023), so its force is Stokes
    // drag toward U_s within the hindrance (1 - phi)^-4.65 - 1 = 1.1 %.
    const double l = 15;
    Particles p = test::random_particles(500, l, 0.5, 4, 9);
    p.add(777, {3, 3, 5000.3}, {0, 0, 2.0}, 1, test::binary_species());
    System sys = gas_only(std::move(p), Domain{l, l}, test::paper_gas(0.41), true, 1e-3);
    const std::size_t top = sys.particles().size() - 1;
    const Vec3 f = sys.particles().force()[top];
    REQUIRE(all_finite(f));
    const double gravity = -2 * kSphere;
    CHECK(f.z - gravity == Approx(kSphere * kA * (0.41 - 2.0)).epsilon(0.012));
    CHECK(sys.slab_fields()->size() == 5001);
    sys.run(1000);  // it keeps moving; the fields follow
    for (const auto& fi : sys.particles().force()) REQUIRE(all_finite(fi));
    CHECK(sys.particles().v()[top].z < 2.0);
}

TEST_CASE("a scene with gas_drag builds slab fields, one without does not", "[physics][gas]") {
    const std::string base =
        "dt = 1e-4\ndomain.lx = 4\ndomain.ly = 4\n"
        "species.names = light heavy\nspecies.density = 1 2\nspecies.diameter = 1 1\n"
        "bed.count = 10 10\nbed.settle = false\n";
    {
        auto t = test::scene_table(base + "effects = gravity\n");
        System s = build_system(t.root(), {1, 0});
        CHECK(s.slab_fields() == nullptr);
        CHECK_FALSE(s.needs().slab_fields);
        CHECK(pressure_drop(s) == 0.0);
    }
    auto t = test::scene_table(base +
                               "effects = gravity gas_drag\ngas_drag.superficial_velocity = 0.19\n"
                               "gas_drag.slab_thickness = 0.5\n");
    System s = build_system(t.root(), {1, 0});
    REQUIRE(s.slab_fields() != nullptr);
    CHECK(s.needs().slab_fields);
    CHECK(s.slab_fields()->thickness() == 0.5);
    // The fields follow outside changes through refresh_forces (as after lifting).
    for (auto& v : s.particles().v()) v = Vec3{0, 0, 0.7};
    s.refresh_forces();
    for (std::size_t j = 0; j < s.slab_fields()->size(); ++j)
        if (s.slab_fields()->solid_volume()[j] > 0)
            CHECK(s.slab_fields()->solid_velocity()[j].z == Approx(0.7).epsilon(1e-14));
}
