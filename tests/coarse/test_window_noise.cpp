// cpi.window_auto: the window-noise measurement (estimators/window_noise.hpp) tells the
// ensemble's random walk from fast noise about the slow path by the members' slopes over the
// window's halves, and the window it asks for follows the efficiency model.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/estimators/window_noise.hpp"
#include "coarse/equation_free/projective/multistep_projective_integrator.hpp"
#include "tests/coarse/toy_steppers.hpp"

using namespace efdem::coarse;

namespace {

struct Samples {
    std::vector<double> t;
    std::vector<Eigen::MatrixXd> members;
};

/// R members x dim components sampled every h over [0, w]: a random walk of diffusion q
/// (variance q h per sample) plus white noise of variance s2 on every sample (fast noise whose
/// correlation time is below the sampling interval).
Samples walk_plus_white(double q, double s2, double h, double w, int r, int dim,
                        std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal;
    Samples s;
    Eigen::MatrixXd walk = Eigen::MatrixXd::Zero(r, dim);
    const long n = std::lround(w / h);
    for (long k = 0; k <= n; ++k) {
        if (k > 0)
            for (int i = 0; i < r; ++i)
                for (int j = 0; j < dim; ++j) walk(i, j) += std::sqrt(q * h) * normal(rng);
        Eigen::MatrixXd x = walk;
        for (int i = 0; i < r; ++i)
            for (int j = 0; j < dim; ++j) x(i, j) += std::sqrt(s2) * normal(rng);
        s.t.push_back(static_cast<double>(k) * h);
        s.members.push_back(x);
    }
    return s;
}

// 50 members x 20 components: 49 x 20 = 980 degrees of freedom per variance. The ratio of two
// such (positively correlated) variances scatters by at most sqrt(2/980 + 2/980) = 6.4 %;
// measured over 20 seeds per case: 2.1 % (walk), 3.2 % (fast), 4.9 % (both, W = 20), 3.3 %
// (both, W = 40), the means within 1.2 % of the predicted 2, 8.1, 5 and 3.2. The 15 % tolerances
// are 3 of the largest of those and far below the factor 4 between the regimes told apart. A
// correlation over 980 pairs scatters by 1/sqrt(980) = 0.032 (largest of 20 seeds: 0.095):
// |correlation| < 0.15 is 4.7 of those.
constexpr int kMembers = 50, kDim = 20;

}  // namespace

TEST_CASE("a random walk's half-window slopes scatter twice as much as the window's",
          "[window_noise]") {
    const Samples s = walk_plus_white(1.0, 0.0, 0.1, 20.0, kMembers, kDim, 3);
    const WindowNoise n = window_noise(s.t, s.members, 0.0);
    REQUIRE(n.measured);
    CHECK(n.window == Approx(20.0));
    CHECK(n.ratio == Approx(2.0).epsilon(0.15));
    CHECK(std::abs(n.correlation) < 0.15);                 // successive windows uncorrelated
    CHECK(std::abs(n.fast_time2) / (20.0 * 20.0) < 0.05);  // u ~ 0
}

TEST_CASE("fast noise alone: the half-window slopes scatter eight times as much",
          "[window_noise]") {
    // Discrete white noise: n (n^2 - 1) / (m (m^2 - 1)) with n = 201, m = 100.5: 8.1.
    const Samples s = walk_plus_white(0.0, 1.0, 0.1, 20.0, kMembers, kDim, 5);
    const WindowNoise n = window_noise(s.t, s.members, 0.0);
    REQUIRE(n.measured);
    CHECK(n.ratio == Approx(8.1).epsilon(0.15));
    CHECK(std::abs(n.correlation) < 0.15);       // disjoint halves: independent
    CHECK(n.fast_time2 / (20.0 * 20.0) >= 5.0);  // rho clamped to 7.5: u = 11
}

TEST_CASE("walk plus fast noise: the measured share carries to another window", "[window_noise]") {
    // a = 1.2 q (walk), b = 12 s2 h (white noise sampled every h): u = b / (a W^2) = 1 at
    // W = 20 with q = 1, h = 0.1, s2 = 400: rho = (2 + 8 u) / (1 + u) = 5, c = u W^2 = 400.
    const Samples s = walk_plus_white(1.0, 400.0, 0.1, 20.0, kMembers, kDim, 7);
    const WindowNoise n = window_noise(s.t, s.members, 0.0);
    REQUIRE(n.measured);
    CHECK(n.ratio == Approx(5.0).epsilon(0.15));
    // c from rho: d c / d rho = 6 W^2 / (8 - rho)^2 = 267 at rho = 5; 15 % of rho (0.75) moves
    // c by about 200 = 50 %.
    CHECK(n.fast_time2 == Approx(400.0).epsilon(0.5));
    // A window measured at W = 40 from the same process: u = 0.25, rho = 3.2.
    const Samples l = walk_plus_white(1.0, 400.0, 0.1, 40.0, kMembers, kDim, 9);
    const WindowNoise m = window_noise(l.t, l.members, 0.0);
    REQUIRE(m.measured);
    CHECK(m.ratio == Approx(3.2).epsilon(0.15));
    CHECK(m.fast_time2 == Approx(400.0).epsilon(0.5));
}

TEST_CASE("the efficient window: four healings for a walk, longer with fast noise",
          "[window_noise]") {
    // g(W) = h / W for a walk: within 1/4 of the best efficiency from W = 4 h.
    CHECK(efficient_window(10.0, 0.0, 0.25, 1.0, 200.0, 1.0) == Approx(40.0));
    CHECK(efficient_window(2.0, 0.0, 0.25, 1.0, 200.0, 1.0) == Approx(8.0));
    CHECK(efficient_window(0.0, 0.0, 0.25, 4.0, 200.0, 1.0) == Approx(4.0));  // the lower bound
    // c = 400, h = 2: g(45) = 0.251, g(46) = 0.241.
    CHECK(window_inefficiency(45.0, 2.0, 400.0) > 0.25);
    CHECK(efficient_window(2.0, 400.0, 0.25, 4.0, 200.0, 1.0) == Approx(46.0));
    CHECK(efficient_window(2.0, 400.0, 0.25, 4.0, 30.0, 1.0) == Approx(30.0));  // the upper bound
}

TEST_CASE("no measurement without two realizations or enough samples", "[window_noise]") {
    const Samples one = walk_plus_white(1.0, 0.0, 0.1, 20.0, 1, kDim, 3);
    CHECK_FALSE(window_noise(one.t, one.members, 0.0).measured);
    const Samples s = walk_plus_white(1.0, 0.0, 1.0, 3.0, kMembers, kDim, 3);  // 4 samples
    CHECK_FALSE(window_noise(s.t, s.members, 1.5).measured);  // 2 samples in the window
}

namespace {

/// A toy ensemble whose members are a random walk (OuEnsembleStepper with k = 1e-4 on 10
/// components, sigma 0.05: q = 0.0025 per unit time) seen through white noise of standard
/// deviation `white` on every sample (fast fluctuations about the slow path, uncorrelated from
/// one sample to the next). The noise is not part of the state: a lift moves the walk.
class WalkSeenThroughNoise final : public efdem::test::OuEnsembleView {
  public:
    WalkSeenThroughNoise(double white, std::uint64_t seed)
        : OuEnsembleView(efdem::test::OuEnsembleStepper(Eigen::VectorXd::Constant(10, 1e-4), 0.05,
                                                        8, 0.1, Eigen::VectorXd::Zero(10), seed)),
          white_(white),
          rng_(seed + 99) {}
    void run(double duration, BurstSamples& out) override {
        const std::size_t first = out.t.size();
        toy_.run(duration, out);
        std::normal_distribution<double> normal;
        for (std::size_t k = first; k < out.t.size(); ++k) {
            for (Eigen::Index r = 0; r < out.members[k].rows(); ++r)
                for (Eigen::Index i = 0; i < out.members[k].cols(); ++i)
                    out.members[k](r, i) += white_ * normal(rng_);
            out.x[k] = out.members[k].colwise().mean().transpose();
        }
    }

  private:
    double white_;
    std::mt19937_64 rng_;
};

/// The windows an adaptive run with cpi.window_auto (healing 1, first window 5, samples every
/// 0.1) chooses on that toy, one per accepted burst.
std::vector<double> auto_windows(double white, std::uint64_t seed) {
    WalkSeenThroughNoise toy(white, seed);
    MultistepSettings s;
    s.burst.healing = 1.0;
    s.burst.window = 5.0;
    s.control = {.tolerance = 0.05, .dt_min = 1.0, .dt_max = 40.0};
    s.dt_quantum = 0.1;
    s.window_auto = true;
    s.window_min = 0.4;
    s.window_max = 40.0;
    MultistepProjectiveIntegrator integrator(s);
    integrator.set_end_time(400.0);
    std::vector<double> windows;
    while (400.0 - toy.time() >= 2.0 * 40.0) {
        const ProjectiveStepRecord r = integrator.step(toy);
        REQUIRE(r.advanced());
        // Every burst is as long as the healing and the window chosen before it.
        if (!windows.empty() && r.lifted) CHECK(r.burst_length == Approx(1.0 + windows.back()));
        if (std::isfinite(r.controller.window_next)) windows.push_back(r.controller.window_next);
    }
    return windows;
}

}  // namespace

TEST_CASE("cpi.window_auto: four healings for a random walk, longer with fast noise",
          "[unit][coarse][window_noise]") {
    // Walk only: c ~ 0, g(W) = h / W: W = 4 h = 4. Seen through white noise of variance
    // s2 = 9 q per sample: a = 1.2 q, b = 12 s2 x 0.1, c = b / a = s2 / q = 9: g(W) = 1 / W +
    // 9 / W^2 (1 + 1 / W) <= 1/4 from W = 9. c is a running mean over 4 bursts of 8 members x
    // 10 components; measured with these seeds, one window scatters by 0.25-0.4 (walk, bounded
    // below by 4) and 0.85-1.0 (fast) about means of 4.34-4.55 and 8.7-9.6, the extremes 5.7
    // and 7.4. The run's mean window (18-34 of them, about a quarter independent) is known to
    // about 0.4 (fast): within 9 +- 1.25 is 3 of those; the walk's mean lies above 4 by the
    // bound. Every fast window above every walk window: the two regimes are told apart burst
    // by burst.
    for (const std::uint64_t seed : {1, 2}) {
        INFO("seed " << seed);
        const std::vector<double> walk = auto_windows(0.0, seed), fast = auto_windows(0.15, seed);
        REQUIRE(walk.size() >= 8);
        REQUIRE(fast.size() >= 8);
        auto mean = [](const std::vector<double>& w) {
            double sum = 0.0;
            for (std::size_t i = 4; i < w.size(); ++i) sum += w[i];  // after the first 4 bursts
            return sum / static_cast<double>(w.size() - 4);
        };
        CHECK(mean(walk) >= 4.0 - 1e-9);
        CHECK(mean(walk) <= 5.0);
        CHECK(mean(fast) == Approx(9.0).margin(1.25));
        for (std::size_t i = 4; i < walk.size(); ++i) CHECK(walk[i] < 6.5);
        for (std::size_t i = 4; i < fast.size(); ++i) CHECK(fast[i] > 6.5);
    }
}

namespace {

/// The walk of WalkSeenThroughNoise (no white noise) with a wave every member shares:
/// amplitude 0.5 and period 2.5 on every component and on the phase signal.
class WalkWithWave final : public efdem::test::OuEnsembleView {
  public:
    explicit WalkWithWave(std::uint64_t seed)
        : OuEnsembleView(efdem::test::OuEnsembleStepper(Eigen::VectorXd::Constant(10, 1e-4), 0.05,
                                                        8, 0.1, Eigen::VectorXd::Zero(10), seed)) {}
    void run(double duration, BurstSamples& out) override {
        const std::size_t first = out.t.size();
        toy_.run(duration, out);
        for (std::size_t k = first; k < out.t.size(); ++k) {
            const double wave = 0.5 * std::sin(2.0 * M_PI * out.t[k] / 2.5);
            out.members[k].array() += wave;
            out.x[k].array() += wave;
            out.phase_signal[k] += wave;
            out.member_phase[k].array() += wave;
        }
    }
};

}  // namespace

TEST_CASE("cpi.window_auto keeps whole wave periods", "[unit][coarse][window_noise]") {
    // A walk alone asks for W = 4 h = 4 (above); a wave of period 2.5 in the ensemble mean
    // makes it whole periods, at least two: 5.
    WalkWithWave toy(3);
    MultistepSettings s;
    s.burst.healing = 1.0;
    s.burst.window = 8.0;
    s.control = {.tolerance = 0.05, .dt_min = 1.0, .dt_max = 40.0};
    s.dt_quantum = 0.1;
    s.drift_rate = 1e6;  // the wave guard on; no burst is a fast transient
    s.window_auto = true;
    s.window_min = 0.4;
    s.window_max = 40.0;
    MultistepProjectiveIntegrator integrator(s);
    integrator.set_end_time(200.0);
    int windows = 0;
    while (200.0 - toy.time() >= 2.0 * 40.0) {
        const ProjectiveStepRecord r = integrator.step(toy);
        REQUIRE(r.advanced());
        if (!std::isfinite(r.controller.window_next)) continue;
        ++windows;
        INFO("window " << r.controller.window_next);
        CHECK(r.controller.window_next >= 5.0 - 1e-9);
        // A whole number of periods, to the sampling grid.
        const double periods = r.controller.window_next / 2.5;
        CHECK(std::abs(periods - std::round(periods)) < 0.1 / 2.5 + 1e-9);
    }
    CHECK(windows >= 5);
}
