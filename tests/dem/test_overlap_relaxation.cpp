// dem::relax_overlaps (dem/beds/overlap_relaxation.hpp) on arrangements whose answer is known:
// a pair across the periodic boundary, a sphere through the floor and the lid, heights held in
// their band, and a case it cannot solve, which it must report instead of hiding.
#include <catch2/catch.hpp>

#include <cmath>

#include "dem/beds/overlap_relaxation.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;

namespace {

dem::Particles pair_at(const Vec3& a, const Vec3& b) {
    const auto species = test::two_size_species(2.0);
    dem::Particles p;
    p.add(1, a, {0.1, 0, 0}, 0, species);  // small, d = 1
    p.add(2, b, {0, 0.2, 0}, 1, species);  // large, d = 2
    return p;
}

}  // namespace

TEST_CASE(
    "relax_overlaps separates a pair across the periodic boundary along its line of "
    "centres",
    "[relaxation]") {
    const dem::Domain box{6.0, 6.0};
    // Centres 0.9 apart through x = 0 (reach 1.5): overlap 0.6 = 0.4 of the mean diameter.
    dem::Particles p = pair_at({0.3, 3.0, 5.0}, {5.4, 3.0, 5.0});
    const dem::OverlapRelaxationReport r = dem::relax_overlaps(p, box);
    CHECK(r.converged);
    CHECK(r.max_overlap_before == Approx(0.4));
    const Vec3 d = box.minimum_image(p.x()[0] - p.x()[1]);
    CHECK(norm(d) >= 1.5 * (1 - 1e-4));
    // Along the line of centres only: y and z unchanged; the pair's midpoint stays (each moves
    // half the overlap).
    CHECK(p.x()[0].y == 3.0);
    CHECK(p.x()[1].z == 5.0);
    CHECK(box.minimum_image(p.x()[0] + p.x()[1] - Vec3{0.3 + 5.4, 6.0, 10.0}).x ==
          Approx(0).margin(1e-12));
    // Positions only: velocities and order untouched.
    CHECK(p.v()[0].x == 0.1);
    CHECK(p.v()[1].y == 0.2);
    CHECK(p.tag()[0] == 1);
}

TEST_CASE("relax_overlaps lifts a sphere out of the floor and holds heights in their band",
          "[relaxation]") {
    const dem::Domain box{6.0, 6.0, 10.0};  // with a lid at z = 10
    SECTION("floor") {
        // The small one 0.2 into the floor (0.2 of its diameter), the large 0.2 into the lid (0.1).
        dem::Particles p = pair_at({1, 1, 0.3}, {4, 4, 9.2});
        const auto r = dem::relax_overlaps(p, box);
        CHECK(r.converged);
        CHECK(r.max_overlap_before == Approx(0.2));  // of its diameter
        CHECK(p.x()[0].z >= 0.5 - 1e-4 * 1.0);       // tolerance: a fraction of the diameter
        CHECK(p.x()[1].z <= 9.0 + 1e-4 * 2.0);
    }
    SECTION("a band too narrow to resolve the overlap is reported, not hidden") {
        // Two spheres on one vertical line, 0.5 apart: only z can separate them, and the band
        // allows 0.1 each.
        dem::Particles p = pair_at({3, 3, 4.0}, {3, 3, 4.5});
        dem::OverlapRelaxationSettings s;
        s.height_band = 0.1;
        s.max_iterations = 500;
        const auto r = dem::relax_overlaps(p, box, s);
        CHECK_FALSE(r.converged);
        CHECK(r.iterations == 500);
        CHECK(r.max_overlap_after > 0.3);  // (1.5 - 0.7) / 1.5
        CHECK(r.max_height_change == Approx(0.1));
    }
}
