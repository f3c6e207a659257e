// Slope estimators (physics.md §10): least squares over the post-healing window, and the
// period-mean estimator that is unbiased for an oscillation on top of a trend.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

#include "coarse/equation_free/estimators/slope_estimators.hpp"
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

/// 99 before t = 104.95, then a + b t: a window from 105 must see only the line.
std::vector<Eigen::VectorXd> line_after_junk(const std::vector<double>& t, const Eigen::Vector3d& a,
                                             const Eigen::Vector3d& b) {
    std::vector<Eigen::VectorXd> x;
    for (double s : t)
        x.push_back(s < 104.95 ? Eigen::VectorXd(Eigen::Vector3d(99, 99, 99))
                               : Eigen::VectorXd(a + b * s));
    return x;
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
    const std::vector<Eigen::VectorXd> x = line_after_junk(t, a, b);
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

TEST_CASE("the increment slope is exact on a line, sits at the window's middle, needs two samples",
          "[unit][coarse]") {
    const auto t = sample_times(100.0, 0.1, 101);
    const Eigen::Vector3d a(1.0, -2.0, 40.0), b(0.3, -0.01, 0.0);
    const std::vector<Eigen::VectorXd> x = line_after_junk(t, a, b);
    const SlopeEstimate est = window_slope(SlopeFit::increment, t, x, 105.0);
    REQUIRE(est.ok);
    CHECK(est.n_samples == 51);
    CHECK(est.t_first == Approx(105.0));
    CHECK(est.t_last == Approx(110.0));
    CHECK(est.t_mean == Approx(107.5));
    // One difference of values O(40) over 5: round-off 1e-13.
    CHECK((est.slope - b).cwiseAbs().maxCoeff() < 1e-12);
    const SlopeEstimate two = increment_slope(t, x, 109.9);  // exactly two samples: a slope
    REQUIRE(two.ok);
    CHECK(two.n_samples == 2);
    CHECK((two.slope - b).cwiseAbs().maxCoeff() < 1e-9);
    const SlopeEstimate none = increment_slope(t, x, 110.0);
    CHECK_FALSE(none.ok);
    CHECK_THAT(none.message, Catch::Contains("at least 2 samples"));
    CHECK(walk_slope_variance_factor(SlopeFit::increment) == 1.0);
    CHECK(walk_slope_variance_factor(SlopeFit::least_squares) == 1.2);
}

TEST_CASE("on a walk the increment slope has 1/1.2 of least squares' variance", "[unit][coarse]") {
    // 4,000 walks (q = 1 per unit) sampled every 0.1 over W = 20 (201 samples): Var(increment) =
    // q / W = 0.05 exactly, Var(least squares) = 1.2 q / W (0.5 % less for 201 samples). Each
    // variance from 4,000 draws is within 2.2 % (1 s.d.); the bounds are 4 s.d.
    efdem::RandomStream rng(11, 0, "test-walk-slopes");
    const auto t = sample_times(0.0, 0.1, 201);
    double v_inc = 0.0, v_ls = 0.0;
    const int draws = 4000;
    for (int d = 0; d < draws; ++d) {
        std::vector<Eigen::VectorXd> x(t.size(), Eigen::VectorXd::Zero(1));
        for (std::size_t k = 1; k < t.size(); ++k)
            x[k][0] = x[k - 1][0] + std::sqrt(0.1) * rng.normal();
        const double inc = increment_slope(t, x, 0.0).slope[0];
        const double ls = least_squares_slope(t, x, 0.0).slope[0];
        v_inc += inc * inc;
        v_ls += ls * ls;
    }
    v_inc /= draws;
    v_ls /= draws;
    CHECK(v_inc == Approx(1.0 / 20.0).epsilon(0.09));
    CHECK(v_ls == Approx(1.2 / 20.0).epsilon(0.09));
    // The two are correlated (the same walks), so their ratio is sharper than either: it must be
    // above 1.1 (1.2 expected).
    CHECK(v_ls / v_inc > 1.1);
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

namespace {
/// The members of one synthetic burst: member r, node i at sample k is beta_i t_k + noise
/// (independent between members and nodes). Before t_window the noise is 100 times larger,
/// so an estimate that used the healing samples would be far off.
struct NoisyMembers {
    std::vector<double> t;
    std::vector<Eigen::MatrixXd> members;
    std::vector<Eigen::VectorXd> mean;
};

/// rho = 0: white noise of std sigma; 0 < rho < 1: a stationary AR(1) series per member and
/// node, e_k = rho e_(k-1) + sqrt(1 - rho^2) sigma eta_k (std sigma, correlation rho^lag).
NoisyMembers noisy_members(efdem::RandomStream& rng, int n_members, int dim,
                           const std::vector<double>& t, double t_window, double sigma,
                           double rho) {
    NoisyMembers b;
    b.t = t;
    Eigen::MatrixXd e(n_members, dim);
    for (Eigen::Index j = 0; j < e.size(); ++j) e.data()[j] = sigma * rng.normal();
    for (double tk : t) {
        for (Eigen::Index j = 0; j < e.size(); ++j)
            e.data()[j] = rho * e.data()[j] + std::sqrt(1.0 - rho * rho) * sigma * rng.normal();
        Eigen::MatrixXd x(n_members, dim);
        for (int i = 0; i < dim; ++i)
            x.col(i) = Eigen::VectorXd::Constant(n_members, (0.1 + 0.05 * i) * tk) +
                       (tk < t_window ? 100.0 : 1.0) * e.col(i);
        b.members.push_back(x);
        b.mean.push_back(x.colwise().mean().transpose());
    }
    return b;
}

double sum_sq_time_deviation(std::span<const double> t) {
    double mean = 0.0, s = 0.0;
    for (double v : t) mean += v / static_cast<double>(t.size());
    for (double v : t) s += (v - mean) * (v - mean);
    return s;
}
}  // namespace

TEST_CASE("members' slopes: their mean is the ensemble slope, their spread / sqrt(R) its s.e.",
          "[unit][coarse]") {
    // R = 8 members, 4 nodes, white noise sigma = 0.3; window of 21 samples after 10 healing
    // samples. The closed form: SE^2 = sigma^2 / (R sum_k (t_k - tbar)^2) over the window.
    constexpr int kMembers = 8, kDim = 4, kTrials = 2000;
    constexpr double kSigma = 0.3;
    const auto t = sample_times(50.0, 0.5, 31);
    const double t_window = t[10];
    const double stt = sum_sq_time_deviation(std::span<const double>(t).subspan(10));
    const double expected_se2 = kSigma * kSigma / (stt * kMembers);
    efdem::RandomStream rng(16, 0, "test-member-slopes");
    double mean_se2 = 0.0;
    for (int trial = 0; trial < kTrials; ++trial) {
        const NoisyMembers b = noisy_members(rng, kMembers, kDim, t, t_window, kSigma, 0.0);
        const Eigen::MatrixXd slopes = member_least_squares_slopes(b.t, b.members, t_window);
        REQUIRE(slopes.rows() == kMembers);
        REQUIRE(slopes.cols() == kDim);
        if (trial == 0) {  // least squares is linear in X: the mean of the slopes is the slope
            const SlopeEstimate ensemble = least_squares_slope(b.t, b.mean, t_window);
            const Eigen::VectorXd mean_slope = slopes.colwise().mean().transpose();
            CHECK((mean_slope - ensemble.slope).cwiseAbs().maxCoeff() < 1e-12);
        }
        const Eigen::VectorXd se = member_slope_standard_error(b.t, b.members, t_window);
        REQUIRE(se.size() == kDim);
        mean_se2 += se.squaredNorm() / (kDim * kTrials);
    }
    // Squares are compared: SE^2 is unbiased, SE itself is low by c4(8) = 0.965 on average.
    // SE^2 estimated with R - 1 = 7 degrees of freedom has relative std sqrt(2/7); averaged over
    // 2000 trials x 4 independent nodes, the mean's relative std is sqrt(2/7/8000) = 0.6 %.
    // 3 % is 5 of those: a wrong divisor (R instead of R - 1: -12.5 %, or no sqrt(R): x8) or
    // healing samples in the window (noise x100) cannot pass.
    CHECK(mean_se2 == Approx(expected_se2).epsilon(0.03));
}

TEST_CASE(
    "with noise correlated in time the members' s.e. is the slope's real error; the "
    "white-noise formula on the mean's residuals is several times too small",
    "[unit][coarse]") {
    // AR(1) noise with rho = 0.9 (correlation time ~10 samples) over a 41-sample window.
    constexpr int kMembers = 8, kDim = 4, kTrials = 2000;
    constexpr double kSigma = 0.3, kRho = 0.9;
    const auto t = sample_times(0.0, 0.5, 51);
    const double t_window = t[10];
    const auto tw = std::span<const double>(t).subspan(10);
    const double stt = sum_sq_time_deviation(tw);
    efdem::RandomStream rng(17, 0, "test-member-slopes-ar1");
    double member_se2 = 0.0, white_se2 = 0.0, actual_err2 = 0.0;
    for (int trial = 0; trial < kTrials; ++trial) {
        const NoisyMembers b = noisy_members(rng, kMembers, kDim, t, t_window, kSigma, kRho);
        member_se2 += member_slope_standard_error(b.t, b.members, t_window).squaredNorm();
        const SlopeEstimate s = least_squares_slope(b.t, b.mean, t_window);
        const auto xw = std::span<const Eigen::VectorXd>(b.mean).subspan(10);
        for (int i = 0; i < kDim; ++i) {
            const double true_slope = 0.1 + 0.05 * i;
            actual_err2 += (s.slope[i] - true_slope) * (s.slope[i] - true_slope);
            // physics.md §10's white-noise s.e. from the residuals of the one fit to the mean.
            std::vector<double> y;
            for (const auto& x : xw) y.push_back(x[i]);
            const LineFit line = fit_line(tw, y);
            double rss = 0.0;
            for (std::size_t k = 0; k < y.size(); ++k) rss += std::pow(y[k] - line.at(tw[k]), 2);
            white_se2 += rss / static_cast<double>(y.size() - 2) / stt;
        }
    }
    // The members' SE^2 has a relative std of 0.6 % over the 8000 node-trials (as above), the
    // squared actual error sqrt(2/8000) = 1.6 %: 8 % is about 5 combined standard deviations.
    CHECK(member_se2 == Approx(actual_err2).epsilon(0.08));
    // For rho = 0.9 and this window the true SE is about 4.2 times the white-noise one
    // (variance x18, measured in a separate simulation); requiring x3 (variance x9) leaves a
    // wide margin, while a method that measured white noise (ratio 1) fails.
    CHECK(member_se2 > 9.0 * white_se2);
}

TEST_CASE("members' increment slopes: each member's own, their mean the ensemble's",
          "[unit][coarse]") {
    const auto t = sample_times(0.0, 0.5, 21);
    std::vector<Eigen::MatrixXd> members;
    std::vector<Eigen::VectorXd> mean;
    for (double s : t) {
        Eigen::MatrixXd m(3, 2);
        m << 1.0 + 0.1 * s, 2.0 - s, 0.01 * s * s * s, 5.0, -s, 0.2 * s;
        members.push_back(m);
        mean.push_back(m.colwise().mean().transpose());
    }
    const Eigen::MatrixXd slopes = member_window_slopes(SlopeFit::increment, t, members, 4.0);
    REQUIRE(slopes.rows() == 3);
    // Member 1's first component is 0.01 s^3: its increment over [4, 10] is 0.01 x 936 / 6 =
    // 1.56, where least squares gives 1.53 (a cubic tells the two fits apart).
    CHECK(slopes(0, 0) == Approx(0.1));
    CHECK(slopes(0, 1) == Approx(-1.0));
    CHECK(slopes(1, 0) == Approx(1.56));
    CHECK(slopes(2, 1) == Approx(0.2));
    const Eigen::VectorXd ensemble = increment_slope(t, mean, 4.0).slope;
    CHECK((slopes.colwise().mean().transpose() - ensemble).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("the members' s.e. needs two members, members for every sample, and a window",
          "[unit][coarse]") {
    efdem::RandomStream rng(18, 0, "test-member-slopes-edge");
    const auto t = sample_times(0.0, 0.5, 11);
    const NoisyMembers one = noisy_members(rng, 1, 3, t, 0.0, 0.3, 0.0);
    CHECK(member_least_squares_slopes(one.t, one.members, 0.0).rows() == 1);
    CHECK(member_slope_standard_error(one.t, one.members, 0.0).size() == 0);  // R = 1: no spread
    CHECK(member_slope_standard_error(t, {}, 0.0).size() == 0);               // no members
    const NoisyMembers two = noisy_members(rng, 2, 3, t, 0.0, 0.3, 0.0);
    CHECK(member_slope_standard_error(two.t, two.members, 0.0).size() == 3);
    CHECK(member_slope_standard_error(two.t, two.members, t.back()).size() == 0);  // 1 sample
    auto partial = std::span<const Eigen::MatrixXd>(two.members).first(5);
    CHECK(member_slope_standard_error(two.t, partial, 0.0).size() == 0);  // not one per sample
    auto mixed = two.members;
    mixed[3] = Eigen::MatrixXd::Zero(3, 3);
    CHECK(member_slope_standard_error(two.t, mixed, 0.0).size() == 0);  // shapes differ
}
