#include <cmath>

#include <catch2/catch.hpp>

#include "core/periodic.hpp"

using efdem::minimum_image_xy;
using efdem::Vec3;
using efdem::wrap_xy;

TEST_CASE("wrap_xy maps into the half-open box, also from just below 0", "[unit][core]") {
    const double lx = 7.5, ly = 3.0;
    // -1e-17 / 7.5 rounds to -1.3e-18; floor gives -1 and x + lx rounds to exactly 7.5 in double:
    // without the guard the wrapped x would equal lx, outside [0, lx).
    const double tiny = -1e-17;
    REQUIRE(tiny + lx == lx);  // the rounding the guard is for
    const Vec3 w = wrap_xy({tiny, tiny, 2.0}, lx, ly);
    CHECK(w.x >= 0.0);
    CHECK(w.x < lx);
    CHECK(w.y >= 0.0);
    CHECK(w.y < ly);
    CHECK(w.z == 2.0);  // z is never periodic
    // Several boxes away, on both sides: the same point in the box (to rounding).
    const Vec3 far = wrap_xy({1.25 + 3 * lx, 0.5 - 4 * ly, -1.0}, lx, ly);
    CHECK(far.x == Approx(1.25).margin(1e-12));
    CHECK(far.y == Approx(0.5).margin(1e-12));
    CHECK(far.z == -1.0);
}

TEST_CASE("minimum_image_xy gives the nearest image of a separation", "[unit][core]") {
    const double lx = 10.0, ly = 4.0;
    const Vec3 d = minimum_image_xy({9.0, -3.5, 5.0}, lx, ly);
    CHECK(d.x == Approx(-1.0));
    CHECK(d.y == Approx(0.5));
    CHECK(d.z == 5.0);
    for (double x : {-14.9, -5.1, -0.2, 4.9, 5.1, 23.7}) {
        const Vec3 m = minimum_image_xy({x, 0.0, 0.0}, lx, ly);
        CHECK(std::abs(m.x) <= lx / 2 + 1e-12);
        // The image differs from the separation by a whole number of boxes.
        CHECK(std::remainder(m.x - x, lx) == Approx(0.0).margin(1e-12));
    }
}
