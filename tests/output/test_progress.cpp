#include <catch2/catch.hpp>

#include <cmath>

#include "mpi_driver/output/progress.hpp"

using efdem::mpi_driver::Progress;

TEST_CASE("progress counts a restarted run's rate and time left from the restart",
          "[unit][progress]") {
    // A run over t = 0..1000, restarted at t = 400 with 4e9 particle-steps already done. This
    // process then does 1e8 particle-steps in 10 s to reach t = 410.
    Progress p(0.0, 1000.0, 0.0);
    p.resume(400.0, 4e9);
    const Progress::Figures f = p.figures(410.0, 4.1e9, 10.0);
    CHECK(f.shown == Approx(0.41));
    CHECK(f.rate == Approx(1e7));  // 1e8 in 10 s, not 4.1e9 / 10 s
    // Direct pace: 10 s per 10 units, 590 units left.
    CHECK(f.eta == Approx(590.0));

    // A CPI run: the work is the particle-steps expected (a jump advances time for free).
    p.set_expected_particle_steps(5.1e9);
    CHECK(p.figures(410.0, 4.1e9, 10.0).eta == Approx(100.0));  // 1e9 left at 1e8 per 10 s
}

TEST_CASE("progress without a restart and before any work", "[unit][progress]") {
    Progress p(100.0, 300.0, 0.0);  // a run that starts at t = 100 (after a warm-up, say)
    const Progress::Figures none = p.figures(100.0, 0.0, 1.0);
    CHECK(none.rate == 0.0);
    CHECK(std::isnan(none.eta));  // nothing done: no estimate, shown as "-"
    const Progress::Figures f = p.figures(150.0, 2e8, 20.0);
    CHECK(f.shown == Approx(0.25));
    CHECK(f.rate == Approx(1e7));
    CHECK(f.eta == Approx(60.0));  // 150 units left at 2.5 units per second
    CHECK(p.figures(300.0, 8e8, 80.0).eta == 0.0);
}
