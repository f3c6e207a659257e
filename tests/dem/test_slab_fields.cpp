// SlabFields (physics.md §4): exact partial volumes, volume conservation, the floor convention,
// particles far above the bed, and u_s as the volume-weighted mean velocity.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>

#include "dem/gas/slab_fields.hpp"
#include "tests/support/dem_fixtures.hpp"
#include "tests/support/fp_traps.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kSphere = kPi / 6.0;  // volume of a sphere of diameter 1

/// Volume of a cap of height h (0 <= h <= 2r): pi h^2 (3r - h)/3, written independently of
/// sphere_volume_below so that the two formulas check each other.
double cap(double h, double r) {
    h = std::clamp(h, 0.0, 2 * r);
    return kPi * h * h * (3 * r - h) / 3;
}

/// Brute force: the volume of sphere (z, r) between planes a < b, with slab 0 reaching down to
/// -infinity (the floor convention).
double volume_between(double a, double b, double z, double r) {
    return cap(b - (z - r), r) - cap(a - (z - r), r);
}

}  // namespace

TEST_CASE("a sphere is split exactly over the slabs it cuts", "[unit][slabs]") {
    const auto species = test::binary_species();
    Particles p;
    p.add(1, {1, 1, 1.0}, {}, 0, species);   // halves in slabs 0 and 1
    p.add(2, {1, 1, 3.25}, {}, 0, species);  // a cap of height 0.25 below z = 3
    SlabFields s(1.0, 1.0);
    s.update(p, Domain{2, 2});
    REQUIRE(s.size() == 4);  // the highest sphere reaches z = 3.75
    CHECK(s.slab_count(0) == 2);
    CHECK(s.first_slab(0) == 0);
    CHECK(s.weights(0)[0] == Approx(kSphere / 2).epsilon(1e-14));
    CHECK(s.weights(0)[1] == Approx(kSphere / 2).epsilon(1e-14));
    CHECK(s.first_slab(1) == 2);
    CHECK(s.weights(1)[0] == Approx(cap(0.25, 0.5)).epsilon(1e-14));
    CHECK(s.weights(1)[1] == Approx(kSphere - cap(0.25, 0.5)).epsilon(1e-14));
    CHECK(s.slab_volume() == 4.0);
    CHECK(s.phi()[2] == Approx(cap(0.25, 0.5) / 4).epsilon(1e-14));
}

TEST_CASE("slab volumes add up to the particle volume, slab by slab and in total",
          "[unit][slabs]") {
    // Property test on random beds, particles cut by slab boundaries and by the floor (z from
    // -0.3: up to 0.8 d_p below the floor). Round-off: a few ulps per weight, so 1e-12 relative.
    const double l = 6;
    const Particles p = test::random_particles(400, l, -0.3, 15, 7);
    const Domain d{l, l};
    for (double dz : {0.3, 0.7, 1.0, 1.5, 2.5}) {
        INFO("dz = " << dz);
        SlabFields s(dz, 1.0);
        s.update(p, d);
        double total = 0;
        for (std::size_t j = 0; j < s.size(); ++j) total += s.phi()[j] * s.slab_volume();
        CHECK(total == Approx(400 * kSphere).epsilon(1e-12));
        // Each slab against the brute-force volumes (slab 0 extends below the floor).
        for (std::size_t j = 0; j < s.size(); ++j) {
            const double a = j == 0 ? -1e9 : static_cast<double>(j) * dz;
            const double b = static_cast<double>(j + 1) * dz;
            double v = 0;
            Vec3 mom{};
            for (std::size_t i = 0; i < p.size(); ++i) {
                const double vij = volume_between(a, b, p.x()[i].z, 0.5);
                v += vij;
                mom += p.v()[i] * vij;
            }
            CHECK(s.solid_volume()[j] == Approx(v).margin(1e-12));
            if (v > 1e-6) {
                CHECK(s.solid_velocity()[j].x == Approx(mom.x / v).margin(1e-10));
                CHECK(s.solid_velocity()[j].z == Approx(mom.z / v).margin(1e-10));
            }
        }
        // Per particle: non-negative weights that add up to the sphere.
        for (std::size_t i = 0; i < p.size(); ++i) {
            double sum = 0;
            for (double w : s.weights(i)) {
                CHECK(w >= 0);
                sum += w;
            }
            CHECK(sum == Approx(kSphere).epsilon(1e-14));
            CHECK(s.slab_count(i) <= s.max_slabs_per_particle());
        }
    }
}

TEST_CASE("the part of a sphere below the floor is counted in slab 0", "[unit][slabs]") {
    const auto species = test::binary_species();
    Particles p;
    p.add(1, {1, 1, 0.3}, {0, 0, 2}, 0, species);  // reaches 0.2 below z = 0
    SlabFields s(0.5, 1.0);
    s.update(p, Domain{2, 2});
    REQUIRE(s.size() == 2);
    // Slab 0 holds everything below z = 0.5, including the 0.2-high cap below the floor.
    CHECK(s.solid_volume()[0] == Approx(cap(0.7, 0.5)).epsilon(1e-14));
    CHECK(s.solid_volume()[0] > cap(0.7, 0.5) - cap(0.2, 0.5) + 1e-3);
    CHECK(s.solid_volume()[0] + s.solid_volume()[1] == Approx(kSphere).epsilon(1e-14));
    CHECK(s.solid_velocity()[0].z == 2.0);
    // A sphere entirely below the floor (a blown-up state) still counts, whole, in slab 0.
    p.add(2, {1, 1, -3}, {}, 0, species);
    s.update(p, Domain{2, 2});
    CHECK(s.first_slab(1) == 0);
    CHECK(s.slab_count(1) == 1);
    CHECK(s.weights(1)[0] == Approx(kSphere).epsilon(1e-14));
}

TEST_CASE("a particle far above the bed adds empty slabs and nothing else", "[unit][slabs]") {
    Particles p = test::random_particles(50, 4, 0.5, 5, 3);
    const auto species = test::binary_species();
    p.add(99, {1, 1, 1e4 + 0.2}, {0, 0, -3}, 1, species);
    SlabFields s(1.0, 1.0);
    s.update(p, Domain{4, 4});
    CHECK(s.size() == 10001);
    CHECK(s.z_top() == 10001.0);
    CHECK(s.phi()[5000] == 0.0);
    CHECK(s.solid_velocity()[5000] == Vec3{});  // empty: 0, not 0/0
    CHECK(s.solid_velocity()[10000].z == -3.0);
    // A height that could only come from a blown-up run is refused with the particle named.
    p.x()[50].z = 1e12;
    try {
        s.update(p, Domain{4, 4});
        FAIL("expected a RuntimeFailure");
    } catch (const RuntimeFailure& e) {
        CHECK(std::string(e.what()).find("particle 99") != std::string::npos);
    }
    // So is a position that is not a number (it would convert to a garbage slab index). The
    // vectorized kernel compares it with a signalling compare, which the tests' floating-point
    // traps would turn into SIGFPE: a NaN is an input here, not something the kernel made.
    p.x()[50].z = std::numeric_limits<double>::quiet_NaN();
    const test::FpTrapsOff traps_off;
    CHECK_THROWS_WITH(s.update(p, Domain{4, 4}),
                      Catch::Contains("particle 99") && Catch::Contains("NaN"));
}

TEST_CASE("the two-slab kernel and the general split give the same fields to the bit",
          "[unit][slabs]") {
    // Spheres no wider than a slab take the vectorized two-slab kernel (dem/gas/slab_split.hpp);
    // a max_diameter just above dz forces the general loop on the same particles. Both compute
    // the same cap differences in the same order, so every weight and field must be equal
    // exactly (==, no tolerance): a difference would mean the kernels disagree on a slab index.
    const double l = 5;
    Particles p = test::random_particles(300, l, -0.3, 12, 11);
    const auto species = test::binary_species();
    p.add(500, {1, 1, 0.5}, {0, 0, 1}, 0, species);  // top exactly on the plane z = 1
    p.add(501, {2, 2, -3}, {0, 0, 1}, 1, species);   // entirely below the floor
    p.add(502, {3, 3, 4.5}, {1, 0, 0}, 0, species);  // bottom exactly on the plane z = 4
    const Domain d{l, l};
    SlabFields fast(1.0, 1.0), general(1.0, 1.0 + 1e-9);
    REQUIRE(fast.max_slabs_per_particle() == 2);
    REQUIRE(general.max_slabs_per_particle() == 3);
    fast.update(p, d);
    general.update(p, d);
    REQUIRE(fast.size() == general.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
        INFO("particle " << i << " at z = " << p.x()[i].z);
        REQUIRE(fast.first_slab(i) == general.first_slab(i));
        REQUIRE(fast.slab_count(i) == general.slab_count(i));
        for (int k = 0; k < fast.slab_count(i); ++k)
            CHECK(fast.weights(i)[k] == general.weights(i)[k]);
    }
    CHECK(fast.slab_count(300) == 1);
    CHECK(fast.slab_count(301) == 1);
    CHECK(fast.first_slab(302) == 4);
    CHECK(fast.slab_count(302) == 1);
    for (std::size_t j = 0; j < fast.size(); ++j) {
        CHECK(fast.phi()[j] == general.phi()[j]);
        CHECK(fast.solid_velocity()[j] == general.solid_velocity()[j]);
    }
}

TEST_CASE("updating the slab fields does not reallocate in steady state", "[unit][slabs]") {
    Particles p = test::random_particles(100, 4, 0, 10, 5);
    SlabFields s(1.0, 1.0);
    s.update(p, Domain{4, 4});
    const double* w = s.weight_data();
    const double* phi = s.phi().data();
    for (auto& x : p.x()) x.z *= 0.9;  // the bed moves but stays below its earlier top
    s.update(p, Domain{4, 4});
    CHECK(s.weight_data() == w);
    CHECK(s.phi().data() == phi);
}
