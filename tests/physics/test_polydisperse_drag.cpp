// gas_drag.polydisperse = van_der_hoef (dem/gas/polydisperse_drag.hpp): the paper's kernel is its
// limit for one size, the force on each size in a uniform array is van der Hoef et al.'s closure
// (without its cubic term) in closed form, the gas force on the particles is the pressure drop
// over the area exactly, and U_mf of one size scales with d^2.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "dem/beds/bed_diagnostics.hpp"
#include "dem/gas/gas_drag.hpp"
#include "dem/gas/slab_fields.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {
constexpr double kSphere = std::numbers::pi / 6.0;

/// Small (d = 1, density 1) and large (diameter `large`, density 2) spheres.
SpeciesTable two_sizes(double large) {
    return SpeciesTable({{"small", 1.0, 1.0}, {"large", 2.0, large}});
}

/// n spheres at random in [0, l)^2 x [z_lo, z_hi), alternating species, with random velocities
/// (or at rest).
Particles spheres(int n, double l, double z_lo, double z_hi, const SpeciesTable& species,
                  std::uint32_t seed, bool moving = true) {
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> ux(0, l), uz(z_lo, z_hi);
    std::normal_distribution<double> nv(0, 1);
    Particles p;
    for (int i = 0; i < n; ++i) {
        const Vec3 v = moving ? Vec3{nv(gen), nv(gen), nv(gen)} : Vec3{};
        p.add(i + 1, {ux(gen), ux(gen), uz(gen)}, v, static_cast<SpeciesId>(i % 2), species);
    }
    return p;
}

System gas_only(Particles p, double l, const SpeciesTable& species, const GasDragSpec& spec) {
    test::EffectList fx;
    fx.gas(spec, species);
    return test::make_system(species, Domain{l, l}, std::move(p), std::move(fx), 1e-4);
}

GasDragSpec polydisperse(double u, double dz = 1.0) {
    GasDragSpec s = test::paper_gas(u, dz);
    s.polydisperse = true;
    return s;
}
}  // namespace

TEST_CASE("one size through the polydisperse closure is the paper's kernel", "[physics][gas]") {
    // Diameter 1 for both species: <d> = 1, Phi u_s - M = 0, and the closure's force is Eq. 1 term
    // by term; only the order of the floating-point operations differs (1e-12 of the largest
    // force). A dense cluster puts some slabs above phi_cap (0.70), so the cap is compared too.
    const double l = 5.0, u = 0.41;
    Particles p = test::random_particles(300, l, -0.3, 12, 11);
    const Particles cluster = test::random_particles(80, l, 13.0, 13.4, 12);
    const auto species = test::binary_species();
    for (std::size_t i = 0; i < cluster.size(); ++i)
        p.add(1000 + static_cast<Tag>(i), cluster.x()[i], cluster.v()[i], cluster.species()[i],
              species);
    System one = gas_only(p, l, species, test::paper_gas(u));
    System poly = gas_only(p, l, species, polydisperse(u));
    double phi_max = 0, scale = 0;
    for (double phi : one.slab_fields()->phi()) phi_max = std::max(phi_max, phi);
    CHECK(phi_max > 0.7);
    for (const Vec3& f : one.particles().force()) scale = std::max(scale, norm(f));
    for (std::size_t i = 0; i < p.size(); ++i)
        CHECK(norm(one.particles().force()[i] - poly.particles().force()[i]) < 1e-12 * scale);
    CHECK(pressure_drop(poly) == Approx(pressure_drop(one)).epsilon(1e-12));
}

TEST_CASE("in a uniform array at rest each size feels van der Hoef's force in closed form",
          "[physics][gas]") {
    // Spheres of diameters 1 and r (1.5, 2, 4) at rest, all inside one slab of thickness 10: every
    // sphere sees the same phi (about 0.3, below the cap) and Sauter mean <d>, and its total gas
    // force (drag plus pressure-gradient force) must be
    //   F_i = (pi/6) A d_i U_s r(phi) (1 - phi)^-2 [ (1 - phi) y_i + phi y_i^2 ],  y_i = d_i/<d>,
    // van der Hoef et al. (2005) without the cubic term, in the units of physics.md §2: 3 pi mu_g
    // d_i U F(phi) with F = (1 - phi)^-4.65 = r(phi)/(1 - phi)^2 (exact to round-off; 1e-12).
    // The horizontal forces vanish (no horizontal slip at rest).
    for (const double large : {1.5, 2.0, 4.0}) {
        INFO("diameter ratio " << large);
        const SpeciesTable species = two_sizes(large);
        const double l = 12.0, u = 0.3, dz = 10.0, r = 0.5 * large;
        // Pairs of one small and one large sphere filling the slab to phi = 0.3.
        const int n =
            2 * static_cast<int>(0.3 * l * l * dz / (kSphere * (1 + large * large * large)));
        System sys =
            gas_only(spheres(n, l, r, dz - r, species, 5, false), l, species, polydisperse(u, dz));
        const SlabFields& slabs = *sys.slab_fields();
        REQUIRE(slabs.size() == 1);
        const double phi = slabs.phi()[0];
        INFO("phi = " << phi);
        REQUIRE(phi < 0.7);
        REQUIRE(phi > 0.15);
        double inv_d = 0.0, volume = 0.0;
        const Particles& p = sys.particles();
        for (std::size_t i = 0; i < p.size(); ++i) {
            const double d = 2.0 * p.radius()[i];
            volume += kSphere * d * d * d;
            inv_d += kSphere * d * d;  // V_i / d_i
        }
        const double mean_d = volume / inv_d;  // Sauter mean
        const double A = test::gas_effect(sys).spec().A;
        const double F = std::pow(1.0 - phi, -2.65) / ((1.0 - phi) * (1.0 - phi));
        for (std::size_t i = 0; i < p.size(); ++i) {
            const double d = 2.0 * p.radius()[i], y = d / mean_d;
            const double expected = kSphere * A * d * u * F * ((1.0 - phi) * y + phi * y * y);
            CHECK(p.force()[i].z == Approx(expected).epsilon(1e-12));
            CHECK(std::abs(p.force()[i].x) < 1e-12 * expected);
        }
        // The pressure drop carries the force on every sphere: the monodisperse law at <d>,
        // A U_s phi F(phi) dz / <d>^2 (sum_i F_i with sum V_i = phi V_slab, sum V_i/d_i =
        // phi V_slab/<d>).
        CHECK(pressure_drop(sys) ==
              Approx(A * u * phi * F * dz / (mean_d * mean_d)).epsilon(1e-12));
    }
}

TEST_CASE("with two sizes the gas force on the particles is the pressure drop over the area",
          "[physics][gas]") {
    // Random moving spheres of diameters 1 and 2 over slabs of 0.5-2 d_p (a large sphere spans up
    // to five), with a dense layer that exercises the cap: the total force equals lx ly sum_j dz
    // (-grad p)_j and the pressure drop its z part over the area, to round-off (1e-12 of the sum
    // of the forces' sizes).
    const SpeciesTable species = two_sizes(2.0);
    const double l = 6.0;
    for (const double dz : {0.5, 1.0, 2.0}) {
        INFO("dz = " << dz);
        Particles p = spheres(300, l, 0.5, 14, species, 21);
        const Particles layer = spheres(120, l, 15.0, 15.6, species, 22);
        for (std::size_t i = 0; i < layer.size(); ++i)
            p.add(1000 + static_cast<Tag>(i), layer.x()[i], layer.v()[i], layer.species()[i],
                  species);
        System sys = gas_only(std::move(p), l, species, polydisperse(0.41, dz));
        const SlabFields& slabs = *sys.slab_fields();
        double phi_max = 0;
        for (double phi : slabs.phi()) phi_max = std::max(phi_max, phi);
        CHECK(phi_max > 0.7);
        std::vector<Vec3> grad(slabs.size());
        test::gas_effect(sys).pressure_gradient(slabs, sys.particles(), grad);
        Vec3 expected{}, f{};
        double scale = 0;
        for (const Vec3& g : grad) expected += g * (l * l * dz);
        for (const Vec3& fi : sys.particles().force()) {
            f += fi;
            scale += norm(fi);
        }
        CHECK(norm(f - expected) < 1e-12 * scale);
        CHECK(std::abs(pressure_drop(sys) - f.z / (l * l)) < 1e-12 * scale);
    }
}

TEST_CASE("U_mf of a layer of one size grows with the square of its diameter", "[physics][gas]") {
    // Drag per unit volume of a sphere among its own kind: A r(phi)/d^2, so the weight per volume
    // (rho) is carried at U_mf = rho d^2 (1 - phi)^2/(A r(phi)) (physics.md §6.1 at d = 1).
    const SpeciesTable species = two_sizes(2.0);
    System sys = gas_only(spheres(4, 4.0, 1, 3, species, 1), 4.0, species, polydisperse(0.1));
    const GasDrag& gas = test::gas_effect(sys);
    const double mono = gas.minimum_fluidization_velocity(2.0, 0.6);
    CHECK(gas.minimum_fluidization_velocity(2.0, 0.6, 2.0) == Approx(4.0 * mono).epsilon(1e-15));
    CHECK(mono == Approx(0.2456).margin(5e-5));  // the heavy species of the paper (§6.1)
}
