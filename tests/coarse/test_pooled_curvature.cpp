// The curvature pooled over several bursts' slopes (cpi.curvature = pooled,
// estimators/pooled_curvature.hpp, docs/error_control.md §3): exact where the slope changes
// linearly, its variance and covariances against a Monte Carlo, what it leaves of a divided
// difference, and — through the integrator on an ensemble walking about an accelerating path —
// that forward Euler's jumps all undershoot by b omega while the jumps that add the pooled
// curvature do not, with their noise what the controller charges.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/coarse_stepper.hpp"
#include "coarse/equation_free/estimators/pooled_curvature.hpp"
#include "coarse/equation_free/projective/multistep_projection.hpp"
#include "coarse/equation_free/projective/multistep_projective_integrator.hpp"
#include "coarse/equation_free/projective/step_size_controller.hpp"
#include "tests/coarse/fixed_schedule.hpp"

using namespace efdem;
using namespace efdem::coarse;

namespace {

/// R members walking about a common path whose slope grows linearly:
/// Y_r(t) = a t + c t^2 / 2 + W_r(t), W_r a Brownian motion with sigma^2 per unit time, sampled
/// every h (the drift over a sample exactly h (a + c (t + h/2))). The ensemble mean's expected
/// flow from X at t is X + a DT + c (t DT + DT^2 / 2): a constant curvature c, as the tall bed's
/// median light height at U_s = 0.19 rises 0.9, 1.6 and 2.2 d_p over successive 200 units. A
/// lift sets every member to the target (the spread collapses, as cpi.lift = mean does).
class QuadraticWalkStepper final : public CoarseStepper {
  public:
    QuadraticWalkStepper(Eigen::Index dim, int members, double a, double c, double sigma, double h,
                         std::uint64_t seed)
        : a_(a), c_(c), sigma_(sigma), h_(h), y_(Eigen::MatrixXd::Zero(members, dim)) {
        for (int r = 0; r < members; ++r)
            rng_.emplace_back(seed * 1000 + static_cast<std::uint64_t>(r));
    }
    double time() const override { return t_; }
    void run(double duration, BurstSamples& out) override {
        const long n = std::lround(duration / h_);
        std::normal_distribution<double> normal;
        for (long s = 0; s < n; ++s) {
            const double drift = h_ * (a_ + c_ * (t_ + 0.5 * h_));
            for (Eigen::Index r = 0; r < y_.rows(); ++r)
                for (Eigen::Index i = 0; i < y_.cols(); ++i)
                    y_(r, i) +=
                        drift + sigma_ * std::sqrt(h_) * normal(rng_[static_cast<std::size_t>(r)]);
            ++steps_;
            t_ = t_lift_ + static_cast<double>(steps_) * h_;
            out.t.push_back(t_);
            out.x.push_back(y_.colwise().mean().transpose());
            out.members.push_back(y_);
            out.phase_signal.push_back(out.x.back()[0]);
            out.member_phase.push_back(y_.col(0));
        }
    }
    void lift(const Eigen::VectorXd& target, double new_time) override {
        y_.rowwise() = target.transpose();
        t_lift_ = t_ = new_time;
        steps_ = 0;
    }
    /// The expected increment of the mean over [t, t + dt].
    double exact_increment(double t, double dt) const {
        return a_ * dt + c_ * (t * dt + 0.5 * dt * dt);
    }

  private:
    double a_, c_, sigma_, h_;
    Eigen::MatrixXd y_;
    std::vector<std::mt19937_64> rng_;
    double t_ = 0.0, t_lift_ = 0.0;
    long steps_ = 0;
};

std::vector<SlopeNode> linear_slopes(double a, double c, const std::vector<double>& taus,
                                     const std::vector<double>& se, Eigen::Index dim) {
    std::vector<SlopeNode> nodes;
    for (std::size_t k = 0; k < taus.size(); ++k)
        nodes.push_back({taus[k], Eigen::VectorXd::Constant(dim, a + c * taus[k]),
                         Eigen::VectorXd::Constant(dim, se[k])});
    return nodes;
}

/// ranks_h2w18's schedule with a fixed DT: bursts of 2 + 18, DT = 80.
MultistepSettings bed_schedule(bool pooled_curvature) {
    MultistepSettings s = test::fixed_schedule(2.0, 18.0, 80.0);
    s.pooled_curvature = pooled_curvature;
    return s;
}

}  // namespace

TEST_CASE("a pooled curvature is exact where the slope changes linearly",
          "[unit][coarse][pooled_curvature]") {
    const std::vector<double> taus{11.0, 111.0, 171.0, 291.0};
    // Unequal standard errors, one of them 0 in component 2: a line through exact slopes is
    // found whatever they are.
    std::vector<SlopeNode> nodes = linear_slopes(0.004, 1.5e-5, taus, {1e-3, 2e-3, 5e-4, 1e-3}, 3);
    nodes[1].se[2] = 0.0;
    const PooledCurvature b = pooled_curvature(nodes);
    REQUIRE(b.bursts() == 4);
    for (Eigen::Index i = 0; i < 3; ++i) CHECK(b.value[i] == Approx(1.5e-5).epsilon(1e-9));
    // c_k = (tau_k - 146) / 41,100 (mean tau 146, sum of squared deviations 41,100), Var(b) =
    // sum_k c_k^2 se_k^2.
    const double s2 = 41100.0 * 41100.0;
    CHECK(b.variance[0] == Approx((135.0 * 135.0 * 1e-6 + 35.0 * 35.0 * 4e-6 +
                                   25.0 * 25.0 * 2.5e-7 + 145.0 * 145.0 * 1e-6) /
                                  s2)
                               .epsilon(1e-9));
    CHECK(b.variance[2] ==
          Approx((135.0 * 135.0 * 1e-6 + 25.0 * 25.0 * 2.5e-7 + 145.0 * 145.0 * 1e-6) / s2)
              .epsilon(1e-9));
    // The last slope is the fit's newest: Cov(b, s_last) = c_last se_last^2 > 0.
    CHECK(b.cov_last()[0] == Approx(145.0 / 41100.0 * 1e-6).epsilon(1e-9));
    // What it leaves of a divided difference of slopes on the same line is nothing.
    const std::vector<SlopeNode> pair{nodes[2], nodes[3]};
    CHECK(curvature_left(pair, b).value.cwiseAbs().maxCoeff() < 1e-15);
}

TEST_CASE("a pooled curvature's variance and covariances are what noisy slopes give",
          "[unit][coarse][pooled_curvature]") {
    // 40,000 draws of four noisy slopes (one component each, unequal s.e.) and of a fifth, the
    // burst after a jump, independent of them. The sample variance of 40,000 values has a
    // relative s.d. of sqrt(2/40,000) = 0.7 %, a covariance's about 1 % of sqrt(Var Var):
    // bounds at 4 %.
    const std::vector<double> taus{11.0, 111.0, 171.0, 291.0};
    const std::vector<double> se{3e-3, 3e-3, 3e-3, 1e-3};
    const double tau_after = 391.0, se_after = 1.5e-3;
    std::vector<SlopeNode> exact = linear_slopes(0.0, 0.0, taus, se, 1);
    const PooledCurvature model = pooled_curvature(exact);
    const SlopeNode after_exact{tau_after, Eigen::VectorXd::Zero(1),
                                Eigen::VectorXd::Constant(1, se_after)};
    const std::vector<SlopeNode> pair_exact{exact.back(), after_exact};
    const DividedDifference left_model = curvature_left(pair_exact, model);
    // A jump of 80 from the last slope (tau 291) at t0 = 300 that adds omega b: its charged
    // variance against the draws' (omega = 80 x 9 + 80^2 / 2 = 3,920).
    const double t0 = 300.0, dt = 80.0;
    const JumpErrorModel jump{{exact.back()}, t0, std::numeric_limits<double>::quiet_NaN(), 1.0, {},
                              model};
    const double omega = omega_integral(jump.nodes, t0, dt);
    REQUIRE(omega == Approx(3920.0));
    const double charged = statistical_error(jump, dt)[0];

    std::mt19937_64 rng(7);
    std::normal_distribution<double> normal;
    const int draws = 40000;
    double bb = 0.0, bs = 0.0, ll = 0.0, jj = 0.0;
    for (int n = 0; n < draws; ++n) {
        std::vector<SlopeNode> nodes = exact;
        for (std::size_t k = 0; k < nodes.size(); ++k) nodes[k].slope[0] = se[k] * normal(rng);
        SlopeNode after = after_exact;
        after.slope[0] = se_after * normal(rng);
        const PooledCurvature b = pooled_curvature(nodes);
        const std::vector<SlopeNode> pair{nodes.back(), after};
        const double left = curvature_left(pair, b).value[0];
        bb += b.value[0] * b.value[0];
        bs += b.value[0] * nodes.back().slope[0];
        ll += left * left;
        const double increment = dt * nodes.back().slope[0] + omega * b.value[0];
        jj += increment * increment;
    }
    INFO("Var(b) " << bb / draws << " vs " << model.variance[0] << "; Cov(b, s_last) " << bs / draws
                   << " vs " << model.cov_last()[0] << "; Var(d - b) " << ll / draws << " vs "
                   << left_model.noise_variance[0]);
    CHECK(bb / draws == Approx(model.variance[0]).epsilon(0.04));
    CHECK(bs / draws == Approx(model.cov_last()[0]).epsilon(0.04));
    CHECK(ll / draws == Approx(left_model.noise_variance[0]).epsilon(0.04));
    // Here omega^2 Var(b) is 18 % of the charged variance and the covariance term 21 %: a formula
    // without either would be off by 4.5 or more times the 4 % bound.
    INFO("jump variance " << jj / draws << " vs charged " << charged * charged);
    CHECK(jj / draws == Approx(charged * charged).epsilon(0.04));
}

TEST_CASE("jumps that add the pooled curvature do not undershoot an accelerating path",
          "[unit][coarse][pooled_curvature][multistep]") {
    // The tall bed at U_s = 0.19 in miniature: a slope 0.005 d_p per unit growing by c = 1.5e-5
    // per unit, 8 members walking with sigma^2 = 2.9e-4 (bench/walk_budget.py's q_1), 19
    // components; bursts of 2 + 18 and DT = 80 (ranks_h2w18's schedule), ten jumps. Forward
    // Euler's slope sits 9 units before the jump: every jump misses c omega, omega = 80 x 9 +
    // 80^2 / 2 = 3,920, i.e. 0.059 d_p, within one jump's noise (DT se = 0.11 d_p) but always
    // low. Over 120 seeds x 19 components each jump index's mean error has a standard error of
    // 0.11 / sqrt(2,280) = 0.0023 d_p: forward Euler's mean is -0.059 within 4 of them; with the
    // pooled curvature (from the third burst on, when the pool resolves it) the mean is 0 within
    // 4 of them; each corrected jump's own noise exceeds its charge, and the jumps' errors summed
    // over the run scatter as the charges add up (5 %): the charge is what a jump adds to the run's
    // error.
    const Eigen::Index dim = 19;
    const int members = 8, seeds = 120, jumps = 10;
    const double a = 0.005, c = 1.5e-5, sigma = std::sqrt(2.9e-4), dt = 80.0;
    const double omega = dt * 9.0 + 0.5 * dt * dt;
    struct Sums {
        std::vector<double> mean = std::vector<double>(jumps, 0.0);
        std::vector<double> square = std::vector<double>(jumps, 0.0);
        std::vector<double> charged2 = std::vector<double>(jumps, 0.0);
        std::vector<long> corrected = std::vector<long>(jumps, 0);
        // The jumps' errors summed over the run so far: its mean and mean square, and the sum
        // of the charges (the growth of that accumulated error's variance, jump by jump).
        std::vector<double> accumulated = std::vector<double>(jumps, 0.0);
        std::vector<double> accumulated2 = std::vector<double>(jumps, 0.0);
        std::vector<double> charged_sum2 = std::vector<double>(jumps, 0.0);
    };
    auto run = [&](bool pooled) {
        Sums s;
        for (std::uint64_t seed = 1; seed <= seeds; ++seed) {
            QuadraticWalkStepper toy(dim, members, a, c, sigma, 0.5, seed);
            MultistepProjectiveIntegrator integrator(bed_schedule(pooled));
            int jump = 0;
            Eigen::ArrayXd accumulated = Eigen::ArrayXd::Zero(dim);
            double charged_sum = 0.0;
            while (jump < jumps) {
                const ProjectiveStepRecord r = integrator.step(toy);
                REQUIRE(r.advanced());
                if (r.status != StepStatus::projected) continue;
                const Eigen::ArrayXd e =
                    r.x_projected.array() - r.x_end.array() - toy.exact_increment(r.t_end, r.dt);
                s.mean[jump] += e.sum() / static_cast<double>(seeds * dim);
                s.square[jump] += e.square().sum() / static_cast<double>(seeds * dim);
                s.charged2[jump] += r.controller.statistical * r.controller.statistical / seeds;
                s.corrected[jump] += r.message.find("adds the curvature") != std::string::npos;
                accumulated += e;
                charged_sum += r.controller.statistical * r.controller.statistical;
                s.accumulated[jump] += accumulated.sum() / static_cast<double>(seeds * dim);
                s.accumulated2[jump] +=
                    accumulated.square().sum() / static_cast<double>(seeds * dim);
                s.charged_sum2[jump] += charged_sum / seeds;
                ++jump;
            }
        }
        return s;
    };
    const Sums euler = run(false), pooled = run(true);
    const double se_mean = dt * sigma / std::sqrt(members * 18.0) / std::sqrt(seeds * dim);
    for (int j = 0; j < jumps; ++j) {
        INFO("jump " << j + 1 << ": forward Euler " << euler.mean[j] << " d_p, pooled "
                     << pooled.mean[j] << " d_p (" << pooled.corrected[j] << " of " << seeds
                     << " corrected); RMS " << std::sqrt(pooled.square[j]) << " vs charged "
                     << std::sqrt(pooled.charged2[j]));
        CHECK(euler.mean[j] == Approx(-c * omega).margin(4.0 * se_mean));
        if (j < 2) continue;  // the pool holds fewer than three bursts
        // From the fourth jump on, four bursts resolve the curvature in nearly every seed.
        if (j >= 3) CHECK(pooled.corrected[j] >= seeds * 9 / 10);
        if (pooled.corrected[j] < seeds * 9 / 10) continue;
        CHECK(std::abs(pooled.mean[j]) < 4.0 * se_mean * 1.2);  // its noise is up to 1.2 x
        // Each corrected jump's own noise is at least its charge: b reuses older bursts' noise,
        // which earlier jumps put into the state with the opposite sign of b's weight there, and
        // the charge is what the jump adds to the run's accumulated error (below).
        CHECK(std::sqrt(pooled.square[j]) > std::sqrt(pooled.charged2[j]));
    }
    // The run's accumulated jump error scatters as the charges add up: its standard deviation
    // over 2,280 sums (120 seeds x 19 components, each the sum of 10 jumps' errors; the bias of
    // the uncorrected first jumps, the same in every sum, taken out) has a relative standard
    // error of 1/sqrt(2 x 2,280) = 1.5 %; within 5 %. Charging each corrected jump its own
    // variance instead overcharges the accumulated error's (printed: the jumps' own variances
    // summed).
    auto sd = [&](const Sums& s) {
        return std::sqrt(s.accumulated2.back() - s.accumulated.back() * s.accumulated.back());
    };
    double own2 = 0.0;
    for (int j = 0; j < jumps; ++j) own2 += pooled.square[j] - pooled.mean[j] * pooled.mean[j];
    INFO("after " << jumps << " jumps: the accumulated error's sd " << sd(pooled) << ", charged "
                  << std::sqrt(pooled.charged_sum2.back()) << ", the jumps' own variances summed "
                  << std::sqrt(own2) << "; forward Euler " << sd(euler) << ", charged "
                  << std::sqrt(euler.charged_sum2.back()));
    CHECK(sd(pooled) == Approx(std::sqrt(pooled.charged_sum2.back())).epsilon(0.05));
    CHECK(sd(euler) == Approx(std::sqrt(euler.charged_sum2.back())).epsilon(0.05));
}

TEST_CASE("a run that adds the pooled curvature resumes from its saved state bit for bit",
          "[unit][coarse][pooled_curvature][multistep]") {
    // Saved after five steps (four bursts in the pool: the next jump adds b). The saved state
    // holds the pool's slopes and the realizations the significance test counts; a state
    // without the latter (a checkpoint written before it) adds no curvature on its first jump.
    const MultistepSettings s = bed_schedule(true);
    QuadraticWalkStepper toy(19, 8, 0.005, 1.5e-5, std::sqrt(2.9e-4), 0.5, 3);
    MultistepProjectiveIntegrator a(s);
    for (int i = 0; i < 5; ++i) REQUIRE(a.step(toy).advanced());
    const IntegratorState saved = a.save_state();
    REQUIRE(saved.has_value());
    CHECK(saved->realizations == 8);
    QuadraticWalkStepper copy = toy, without_copy = toy;
    MultistepProjectiveIntegrator b(s), without(s);
    b.restore_state(saved);
    MultistepState old = *saved;
    old.realizations = 0;
    without.restore_state(old);
    const ProjectiveStepRecord ra = a.step(toy), rb = b.step(copy), rw = without.step(without_copy);
    REQUIRE(ra.status == StepStatus::projected);
    CHECK(ra.message.find("adds the curvature") != std::string::npos);
    CHECK((ra.x_projected.array() == rb.x_projected.array()).all());
    CHECK(rw.message.find("no curvature added") != std::string::npos);
    CHECK_FALSE((rw.x_projected.array() == ra.x_projected.array()).all());
    for (int i = 0; i < 3; ++i) {
        const ProjectiveStepRecord na = a.step(toy), nb = b.step(copy);
        CHECK((na.x_projected.array() == nb.x_projected.array()).all());
    }
    CHECK(a.save_state() == b.save_state());
}
