// Projective Euler over a whole number of travelling-wave periods (DT = k T, period-mean slope)
// on a sine + linear-trend toy: the jump follows the trend exactly for any phase, the burst is
// extended when it holds fewer than two periods, and failures are reported.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "coarse/equation_free/projective/period_projective_euler.hpp"
#include "core/rng.hpp"
#include "tests/coarse/toy_steppers.hpp"

using namespace efdem::coarse;
using efdem::test::MemberTrendStepper;
using efdem::test::SineTrendStepper;

namespace {
constexpr double kPi = std::numbers::pi;
const Eigen::Vector3d kOffset(3.0, -1.0, 20.0), kTrend(0.05, -0.2, 0.01);

SineTrendStepper random_phase_toy(efdem::RandomStream& rng, double period, double h = 0.1) {
    const Eigen::Vector3d phase(rng.uniform(0, 2 * kPi), rng.uniform(0, 2 * kPi),
                                rng.uniform(0, 2 * kPi));
    SineTrendStepper toy(kOffset, kTrend, phase, 1.0, period, h);
    BurstSamples discard;
    toy.run(0.1 * static_cast<double>(rng.below(100)), discard);  // random start time
    return toy;
}
}  // namespace

TEST_CASE("DT = k T lands on the trend line for any phase", "[unit][coarse]") {
    efdem::RandomStream rng(12, 0, "test-period-cpi");
    SECTION("T a multiple of the sampling interval: exact to round-off") {
        // T = 100 h: the period is found to round-off (crossings sampled at the same phase every
        // period) and the period-mean slope is exact, so X_proj - X(t_end) = 2 T beta to
        // round-off of values O(20): 1e-10.
        for (int trial = 0; trial < 50; ++trial) {
            auto toy = random_phase_toy(rng, 10.0);
            PeriodProjectiveEuler cpi(
                {.burst = {.healing = 10, .window = 32}, .periods_per_step = 2});
            const ProjectiveStepRecord rec = cpi.step(toy);
            REQUIRE(rec.status == StepStatus::projected);
            CHECK(rec.period == Approx(10.0).epsilon(1e-10));
            CHECK(rec.periods_per_step == 2);
            CHECK(rec.dt == Approx(20.0).epsilon(1e-10));
            REQUIRE((rec.x_projected - rec.x_end - rec.dt * kTrend).cwiseAbs().maxCoeff() < 1e-10);
        }
    }
    SECTION("any T: within the interpolation bound of the period-mean estimator") {
        // |error| <= DT a w^2 h^2/(4 T) (slope_estimators.hpp) plus the effect of the period's
        // crossing-interpolation error (~1e-5 relative), which is far below that bound.
        for (int trial = 0; trial < 50; ++trial) {
            const double period = rng.uniform(5.0, 14.0), h = 0.1, w = 2 * kPi / period;
            auto toy = random_phase_toy(rng, period, h);
            PeriodProjectiveEuler cpi({.burst = {.healing = 10, .window = 3.2 * period}});
            const ProjectiveStepRecord rec = cpi.step(toy);
            REQUIRE(rec.status == StepStatus::projected);
            CHECK(rec.period == Approx(period).epsilon(1e-4));
            const double bound = rec.dt * w * w * h * h / (4 * period);
            REQUIRE((rec.x_projected - rec.x_end - rec.dt * kTrend).cwiseAbs().maxCoeff() < bound);
        }
    }
}

TEST_CASE("repeated DT = k T steps stay on the true trajectory", "[unit][coarse]") {
    // Lifting keeps the oscillation's phase (reused particles), so after five jumps of 2T the
    // toy must still follow its original trajectory: 1e-9 (five steps of ~1e-13 errors in
    // values O(20), with margin).
    efdem::RandomStream rng(13, 0, "test-period-cpi");
    auto toy = random_phase_toy(rng, 10.0);
    const SineTrendStepper original = toy;
    PeriodProjectiveEuler cpi({.burst = {.healing = 10, .window = 22}});
    for (int i = 0; i < 5; ++i) REQUIRE(cpi.step(toy).status == StepStatus::projected);
    CHECK(toy.lifts == 5);
    for (double dt : {0.0, 3.3, 17.1})
        CHECK((toy.value(toy.time() + dt) - original.value(toy.time() + dt)).cwiseAbs().maxCoeff() <
              1e-9);
}

TEST_CASE("a burst with fewer than two periods is extended, up to the maximum", "[unit][coarse]") {
    efdem::RandomStream rng(14, 0, "test-period-cpi");
    auto toy = random_phase_toy(rng, 10.0);
    // A window of 1.5 periods after healing, extended in steps of 5.
    auto step_with = [&](double max_extension) {
        return PeriodProjectiveEuler({.burst = {.healing = 10, .window = 15},
                                      .max_extension = max_extension,
                                      .extension_step = 5})
            .step(toy);
    };
    SECTION("extended until two periods are seen") {
        const ProjectiveStepRecord rec = step_with(30.0);
        REQUIRE(rec.status == StepStatus::projected);
        CHECK(rec.burst_length > 25.0);
        CHECK(rec.burst_length <= 55.0);
        CHECK_THAT(rec.message, Catch::Contains("burst extended by"));
        CHECK(rec.period == Approx(10.0).epsilon(1e-10));
    }
    SECTION("not enough periods within the maximum: reported, nothing lifted") {
        const ProjectiveStepRecord rec = step_with(4.0);
        CHECK(rec.status == StepStatus::too_few_periods);
        CHECK_FALSE(rec.advanced());
        CHECK(toy.lifts == 0);
        CHECK(rec.burst_length == Approx(29.0));
        CHECK_THAT(rec.message, Catch::Contains("lengthen the burst"));
        CHECK_THAT(rec.message, Catch::Contains("the maximum"));
    }
}

TEST_CASE("DT = k T: k = 0, a missing phase signal, and the stability monitor", "[unit][coarse]") {
    efdem::RandomStream rng(15, 0, "test-period-cpi");
    SECTION("k = 0 runs the burst only") {
        auto toy = random_phase_toy(rng, 10.0);
        PeriodProjectiveEuler cpi({.burst = {.healing = 10, .window = 25}, .periods_per_step = 0});
        const ProjectiveStepRecord rec = cpi.step(toy);
        CHECK(rec.status == StepStatus::burst_only);
        CHECK(rec.dt == 0.0);
        CHECK(toy.lifts == 0);
        CHECK(rec.period == Approx(10.0).epsilon(1e-10));
    }
    SECTION("no phase signal") {
        auto toy = random_phase_toy(rng, 10.0);
        toy.with_phase_signal = false;
        PeriodProjectiveEuler cpi({});
        const ProjectiveStepRecord rec = cpi.step(toy);
        CHECK(rec.status == StepStatus::invalid_burst);
        CHECK_THAT(rec.message, Catch::Contains("phase-signal"));
    }
    SECTION("three periods: the monitor measures no transient in a sine + trend") {
        // Consecutive period-mean slopes are both exactly beta: ratio 1, lambda = 0 (1e-9).
        auto toy = random_phase_toy(rng, 10.0);
        PeriodProjectiveEuler cpi({.burst = {.healing = 10, .window = 35}});
        const ProjectiveStepRecord rec = cpi.step(toy);
        REQUIRE(rec.status == StepStatus::projected);
        CHECK(rec.stability.assessed);
        CHECK(rec.stability.stable);
        CHECK(std::abs(rec.stability.rate) < 1e-9);
    }
}

TEST_CASE("DT = k T records the s.e. of the period-mean slope from the members' own",
          "[unit][coarse]") {
    // Each member's period means over the common T: the shared oscillation and trend cancel in
    // the spread, which is that of the members' own trends d (node 1 has none). Round-off of
    // slopes O(0.1): 1e-9 relative.
    Eigen::MatrixXd d(4, 2);
    d << 0.02, 0.0, -0.01, 0.0, 0.0, 0.0, 0.03, 0.0;
    const double mean = d.col(0).mean();
    const double se0 = std::sqrt((d.col(0).array() - mean).square().sum() / 3.0 / 4.0);
    MemberTrendStepper toy(SineTrendStepper(Eigen::Vector2d(3.0, -1.0), Eigen::Vector2d(0.05, -0.2),
                                            Eigen::Vector2d(0.3, 1.0), 1.0, 10.0, 0.1),
                           d);
    PeriodProjectiveEuler cpi({.burst = {.healing = 10, .window = 32}, .periods_per_step = 2});
    const ProjectiveStepRecord rec = cpi.step(toy);
    REQUIRE(rec.status == StepStatus::projected);
    REQUIRE(rec.slope_standard_error.size() == 2);
    CHECK(rec.slope_standard_error[0] == Approx(se0).epsilon(1e-9));
    CHECK(rec.slope_standard_error[1] < 1e-12);
}
