// Slope estimators (physics.md §10): least squares over the post-healing window, and the
// period-mean estimator that is unbiased for an oscillation on top of a trend.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

#include "coarse/equation_free/slope_estimators.hpp"
#include "core/rng.hpp"

using namespace efdem::coarse;

namespace {
constexpr double kPi = std::numbers::pi;

/// Samples t_k = t0 + k h (by repeated addition, as a micro model's clock does), k = 0..n-1.
std::vector<double> sample_times(double t0, double h, int n) {
    std::vector<double> t;
    double s = t0;
    for (int k = 0; k < n; ++k, s += h) t.push_back(s);
    return t;
}

/// Three components, each an offset + trend + sine with its own phase.
struct SineTrend {
    Eigen::Vector3d offset{3.0, -1.0, 20.0}, trend{0.05, -0.2, 0.0}, phase{0.0, 1.0, 2.0};
    double amplitude = 1.0, period = 10.0;
    Eigen::VectorXd operator()(double t) const {
        Eigen::VectorXd x = offset + trend * t;
        for (int i = 0; i < 3; ++i) x[i] += amplitude * std::sin(2 * kPi * t / period + phase[i]);
        return x;
    }
};
}  // namespace

TEST_CASE("least-squares slope is exact on a line and uses only the window", "[unit][coarse]") {
    // t = 100 + 0.1 k by repeated addition: the window start 105 must still catch the sample
    // that rounding put at 104.99999999999...
    const auto t = sample_times(100.0, 0.1, 101);
    const Eigen::Vector3d a(1.0, -2.0, 40.0), b(0.3, -0.01, 0.0);
    std::vector<Eigen::VectorXd> x;
    for (double s : t)
        x.push_back(s < 104.95 ? Eigen::VectorXd(Eigen::Vector3d(99, 99, 99))
                               : Eigen::VectorXd(a + b * s));
    const SlopeEstimate est = least_squares_slope(t, x, 105.0);
    REQUIRE(est.ok);
    CHECK(est.n_samples == 51);
    CHECK(est.t_first == Approx(105.0));
    // Exact up to round-off of 51-term centred sums of values O(40): 1e-12 absolute.
    CHECK((est.slope - b).cwiseAbs().maxCoeff() < 1e-12);

    SECTION("fewer than two samples in the window is reported, not guessed") {
        const SlopeEstimate none = least_squares_slope(t, x, 110.0);  // only t = 110
        CHECK_FALSE(none.ok);
        CHECK(none.n_samples == 1);
        CHECK_THAT(none.message, Catch::Contains("at least 2 samples"));
    }
}

TEST_CASE("least squares over exactly two periods is biased by up to 0.477 a/T", "[unit][coarse]") {
    // physics.md §10: the bias is (6/pi) a/(m^2 T) at worst, 0.477 a/T for m = 2. The slope is
    // linear in the data, so for a sin(w t + phi) it is a (cos(phi) s_sin + sin(phi) s_cos) and
    // its maximum over all phases is a hypot(s_sin, s_cos), exactly. Equal-weight sums over
    // n = 20001 samples differ from the continuous integrals by O(1/n) ~ 1.5e-4 relative
    // (1.5e-3 was seen at n = 2001): 1e-3.
    const double period = 10.0, a = 1.0;
    const auto t = sample_times(0.0, 2 * period / 20000, 20001);
    auto slope_of = [&](auto f) {
        std::vector<Eigen::VectorXd> x;
        for (double s : t) x.push_back(Eigen::VectorXd::Constant(1, f(2 * kPi * s / period)));
        return least_squares_slope(t, x, 0.0).slope[0];
    };
    const double s_sin = slope_of([](double u) { return std::sin(u); });
    const double s_cos = slope_of([](double u) { return std::cos(u); });
    CHECK(a * std::hypot(s_sin, s_cos) == Approx(6 / kPi / 4 * a / period).epsilon(1e-3));
}

TEST_CASE("interval mean integrates the interpolant exactly", "[unit][coarse]") {
    // A piecewise-linear series is its own interpolant, so any [a, b] is exact: compare with the
    // closed form of a line (1e-12: round-off of ~100 trapezoids of size O(10)).
    efdem::RandomStream rng(6, 0, "test-interval");
    std::vector<double> t{0.0};
    for (int k = 0; k < 100; ++k) t.push_back(t.back() + rng.uniform(0.05, 0.15));
    std::vector<double> y;
    for (double s : t) y.push_back(2.0 - 0.7 * s);
    for (int trial = 0; trial < 100; ++trial) {
        const double a = rng.uniform(0.0, t.back()), b = rng.uniform(0.0, t.back());
        if (std::abs(a - b) < 1e-3) continue;
        const double lo = std::min(a, b), hi = std::max(a, b);
        REQUIRE(interval_mean(t, y, lo, hi) == Approx(2.0 - 0.35 * (lo + hi)).epsilon(1e-12));
    }
}

TEST_CASE("period-mean slope is exact on sine + trend for any phase and sample offset",
          "[unit][coarse]") {
    // T = 100 h: the interpolant of the sine is T-periodic, so both period means are exact
    // (trapezoids of a sine over whole periods sum to zero) wherever t_end falls between
    // samples. Remaining error: round-off of ~200-term sums of values O(20), divided by T:
    // 1e-12 relative to the slope scale |beta| + a/T.
    SineTrend f;
    const double h = f.period / 100;
    efdem::RandomStream rng(7, 0, "test-period-mean");
    for (int trial = 0; trial < 200; ++trial) {
        f.phase = Eigen::Vector3d(rng.uniform(0, 2 * kPi), rng.uniform(0, 2 * kPi),
                                  rng.uniform(0, 2 * kPi));
        const double t0 = rng.uniform(0.0, 50.0);
        const auto t = sample_times(t0, h, 331);  // 3.3 periods
        std::vector<Eigen::VectorXd> x;
        for (double s : t) x.push_back(f(s));
        const double t_end = t.back() - rng.uniform(0.0, 0.3 * f.period);  // off the grid
        const SlopeEstimate est = period_mean_slope(t, x, f.period, t_end);
        REQUIRE(est.ok);
        const double scale = f.trend.cwiseAbs().maxCoeff() + f.amplitude / f.period;
        REQUIRE((est.slope - f.trend).cwiseAbs().maxCoeff() < 1e-12 * scale);
    }
}

TEST_CASE(
    "period-mean slope error stays within the interpolation bound when T is not a "
    "multiple of the sampling interval",
    "[unit][coarse]") {
    // Each period mean of the interpolated sine is off by at most a w^2 h^2/8, so the slope is
    // off by at most a w^2 h^2 / (4 T) (slope_estimators.hpp); the bound must hold for every T.
    SineTrend f;
    const double h = 0.1;
    efdem::RandomStream rng(8, 0, "test-period-mean");
    double worst_ratio = 0.0;
    for (int trial = 0; trial < 200; ++trial) {
        f.period = rng.uniform(5.0, 14.0);
        f.phase = Eigen::Vector3d(rng.uniform(0, 2 * kPi), rng.uniform(0, 2 * kPi),
                                  rng.uniform(0, 2 * kPi));
        const auto t =
            sample_times(rng.uniform(0.0, 10.0), h, static_cast<int>(2.2 * f.period / h));
        std::vector<Eigen::VectorXd> x;
        for (double s : t) x.push_back(f(s));
        const SlopeEstimate est = period_mean_slope(t, x, f.period, t.back());
        REQUIRE(est.ok);
        const double w = 2 * kPi / f.period;
        const double bound = f.amplitude * w * w * h * h / (4 * f.period);
        const double err = (est.slope - f.trend).cwiseAbs().maxCoeff();
        REQUIRE(err <= bound);
        worst_ratio = std::max(worst_ratio, err / bound);
    }
    CHECK(worst_ratio > 1e-3);  // the test sees real interpolation error, not a degenerate case
}

TEST_CASE("period-mean slope reports samples that do not cover two periods", "[unit][coarse]") {
    const auto t = sample_times(0.0, 0.1, 150);  // covers 14.9 < 2 T
    std::vector<Eigen::VectorXd> x(t.size(), Eigen::VectorXd::Zero(2));
    const SlopeEstimate est = period_mean_slope(t, x, 10.0, t.back());
    CHECK_FALSE(est.ok);
    CHECK_THAT(est.message, Catch::Contains("two periods"));
}
