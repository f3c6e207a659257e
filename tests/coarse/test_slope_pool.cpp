// The pooled slope (cpi.slope = pooled, estimators/slope_pool.hpp) and the error budget of
// jumps that reuse bursts, on exact cases and on a noisy SDE with a known mean
// (docs/error_control.md §7): the weights and the node's time, the charged error (the growth of
// the accumulated error's variance), the variance reduction of a pooled slope against the
// predicted factor, the coverage of its predicted band, and — through the integrator — that the
// accumulated error of pooled jumps is what the budget charges, not the sum of their own
// variances.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "coarse/equation_free/estimators/slope_pool.hpp"
#include "coarse/equation_free/projective/multistep_projection.hpp"
#include "coarse/equation_free/projective/multistep_projective_integrator.hpp"
#include "tests/coarse/fixed_schedule.hpp"
#include "tests/coarse/toy_steppers.hpp"

using namespace efdem;
using namespace efdem::coarse;

namespace {

SlopeNode node(double tau, double slope, double se, Eigen::Index dim = 3) {
    return {tau, Eigen::VectorXd::Constant(dim, slope), Eigen::VectorXd::Constant(dim, se)};
}

/// Variance about zero (the errors have mean zero by construction) of a list of samples.
double mean_square(const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x * x;
    return s / static_cast<double>(v.size());
}

}  // namespace

TEST_CASE("a pooled slope is the inverse-variance mean, exact for a linear slope at its time",
          "[unit][coarse][slope_pool]") {
    // Three bursts, s(t) = 1 + 0.1 t exactly, standard errors 1, 1, 2: weights 4/9, 4/9, 1/9.
    SlopePool pool(3);
    pool.add(node(10.0, 2.0, 1.0));
    pool.add(node(30.0, 4.0, 1.0));
    pool.add(node(50.0, 6.0, 2.0));
    const PooledSlope e = pool.estimate(3);
    REQUIRE(e.bursts() == 3);
    CHECK(e.weights[0] == Approx(4.0 / 9.0));
    CHECK(e.weights[2] == Approx(1.0 / 9.0));
    CHECK(e.node.tau == Approx((4.0 * 10 + 4.0 * 30 + 50) / 9.0));
    // Exact for a linear slope at tau_pool: what lets the forward-Euler truncation model of
    // the jump cover the pool's lag.
    CHECK(e.node.slope[1] == Approx(1.0 + 0.1 * e.node.tau));
    // sqrt(sum w^2 se^2) = sqrt((16 + 16 + 4) / 81) = 2/3.
    CHECK(e.node.se[0] == Approx(2.0 / 3.0));
    CHECK(e.committed.isZero());  // no jump has used these bursts
    // A fourth burst pushes the oldest out.
    pool.add(node(70.0, 8.0, 1.0));
    CHECK(pool.size() == 3);
    CHECK(pool.estimate(1).node.tau == 70.0);
    // Without a measured noise (se = 0: a run without members) the weights are equal.
    SlopePool blind(2);
    blind.add(node(0.0, 1.0, 0.0));
    blind.add(node(10.0, 3.0, 0.0));
    CHECK(blind.estimate(2).weights[0] == Approx(0.5));
}

TEST_CASE("the budget charges a pooled jump the growth of the accumulated error's variance",
          "[unit][coarse][slope_pool]") {
    // Bursts of equal noise se = 1, jumps of DT = 10, a pool of m = 4.
    const double dt = 10.0, se = 1.0;
    SlopePool pool(4);
    for (int k = 0; k < 4; ++k) pool.add(node(20.0 * k, 0.0, se));
    // Four bursts no jump has used (a warm-up's windows, direct bursts): the jump's own scatter
    // DT se / 2, and that is all it adds.
    PooledSlope e = pool.estimate(4);
    CHECK(charged_error(e.node.se, e.committed, dt)[0] == Approx(dt * se / 2.0));
    // Jump after jump, each followed by a new burst: once every pooled burst has been used by
    // earlier jumps, each jump adds exactly DT se again — the pooled slopes telescope to the
    // bursts' own (sum over jumps of the moving mean = sum of the bursts), so the accumulated
    // error of a long run is that of one-burst slopes, while each jump's own scatter is halved.
    double accumulated = 0.0;
    for (int jump = 0; jump < 12; ++jump) {
        e = pool.estimate(4);
        const double charged = charged_error(e.node.se, e.committed, dt)[0];
        accumulated += charged * charged;
        CHECK(e.node.se[0] == Approx(se / 2.0));  // the jump's own: sqrt(4 / 16)
        if (jump >= 3) CHECK(charged == Approx(dt * se).epsilon(1e-12));
        pool.commit(e, dt);
        pool.add(node(20.0 * (jump + 4), 0.0, se));
    }
    // The variance the budget accumulated is sum_b a_b^2 se^2 over every burst's commitment:
    // jump j used bursts j..j+3 with weight 1/4, so burst b holds DT/4 x (jumps that used it).
    double expected = 0.0;
    for (int b = 0; b < 16; ++b) {
        int uses = 0;
        for (int j = 0; j < 12; ++j) uses += (b >= j && b <= j + 3);
        expected += std::pow(dt * uses / 4.0 * se, 2);
    }
    CHECK(accumulated == Approx(expected).epsilon(1e-12));
    CHECK(pool.bursts().front().commitment == Approx(0.75 * dt));  // burst 12: jumps 9, 10, 11
}

TEST_CASE("on a noisy SDE a pooled slope's variance and band are what it predicts",
          "[unit][coarse][slope_pool]") {
    // 8 members of dY = -k Y dt + sigma dW (k = 1e-4: the mean slope is known, -k e^(-k t) x0,
    // and barely changes over a pool), bursts of 4 back to back without lifting; every burst's
    // least-squares slope and its members' standard error feed a pool of 4. Errors against the
    // exact mean slope at each estimate's own time.
    const Eigen::Index dim = 19;
    const Eigen::VectorXd k = Eigen::VectorXd::Constant(dim, 1e-4);
    const double x0 = 3.0, window = 4.0;
    std::vector<double> burst_err, pool_err, burst_pred, pool_pred;
    long inside = 0, total = 0;
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
        test::OuEnsembleStepper toy(k, 0.05, 8, 0.1, Eigen::VectorXd::Constant(dim, x0), seed);
        SlopePool pool(4);
        for (int b = 0; b < 60; ++b) {
            BurstSamples s;
            const double t0 = toy.time();
            toy.run(window, s);
            const SlopeEstimate est = least_squares_slope(s.t, s.x, t0);
            REQUIRE(est.ok);
            const Eigen::VectorXd se = member_slope_standard_error(s.t, s.members, t0);
            REQUIRE(se.size() == dim);
            pool.add({est.t_mean, est.slope, se});
            if (pool.size() < 4) continue;
            const PooledSlope p = pool.estimate(4);
            for (Eigen::Index i = 0; i < dim; ++i) {
                const double truth_b = -k[i] * std::exp(-k[i] * est.t_mean) * x0;
                const double truth_p = -k[i] * std::exp(-k[i] * p.node.tau) * x0;
                burst_err.push_back(est.slope[i] - truth_b);
                burst_pred.push_back(se[i]);
                pool_err.push_back(p.node.slope[i] - truth_p);
                pool_pred.push_back(p.node.se[i]);
                // The band the controller uses: +-1.96 standard errors.
                inside += std::abs(p.node.slope[i] - truth_p) <= 1.96 * p.node.se[i];
                ++total;
            }
        }
    }
    // Measured variance reduction against the predicted one (mean se_pool^2 / mean se^2, about
    // 1/4). Over 4 x 57 x 19 = 4,332 errors (consecutive pools share bursts: about a quarter of
    // them independent) the measured ratio scatters by ~6 %; +-25 % is four of those.
    const double measured = mean_square(pool_err) / mean_square(burst_err);
    const double predicted = mean_square(pool_pred) / mean_square(burst_pred);
    INFO("variance ratio pooled / one burst: measured " << measured << ", predicted " << predicted);
    CHECK(predicted == Approx(0.25).epsilon(0.1));
    CHECK(measured / predicted > 0.75);
    CHECK(measured / predicted < 1.33);
    // Coverage of the +-1.96 se band: 95 % for a known se; se is estimated from 8 members per
    // burst, pooled over 4 bursts (~28 degrees of freedom: t-quantile 2.05, so the band holds
    // ~94 %). Correlated samples: +-5 % around it.
    const double coverage = static_cast<double>(inside) / static_cast<double>(total);
    INFO("coverage of the pooled band " << coverage);
    CHECK(coverage > 0.89);
    CHECK(coverage < 0.99);
}

namespace {

/// Per-jump and accumulated errors of fixed-DT forward-Euler CPI on the OU toy (k tiny: the
/// exact coarse flow over a jump is e^(-k DT) X, and an error made early is not damped over the
/// run), with the budget's charged and the jumps' own statistical errors per component.
struct PooledRun {
    std::vector<double> jump_err, jump_pred;   ///< per jump and component: true, own s.e.
    std::vector<double> accumulated;           ///< per seed and component: sum of true errors
    std::vector<double> charged_var, own_var;  ///< per seed and component: sums of squares
};

PooledRun pooled_run(SlopeSource source, std::uint64_t seeds) {
    const Eigen::Index dim = 19;
    const Eigen::VectorXd k = Eigen::VectorXd::Constant(dim, 1e-4);
    PooledRun out;
    for (std::uint64_t seed = 1; seed <= seeds; ++seed) {
        test::OuEnsembleStepper toy(k, 0.05, 8, 0.1, Eigen::VectorXd::Constant(dim, 3.0),
                                    100 + seed);
        MultistepSettings s = test::fixed_schedule(1.0, 4.0, 12.0);
        s.slope = source;
        s.pool = 4;
        MultistepProjectiveIntegrator integrator(s);
        integrator.set_end_time(500.0);
        Eigen::VectorXd sum = Eigen::VectorXd::Zero(dim), charged = sum, own = sum;
        while (500.0 - toy.time() >= 5.0 - 1e-9) {
            const ProjectiveStepRecord r = integrator.step(toy);
            REQUIRE(r.advanced());
            if (r.status != StepStatus::projected || r.dt < 12.0 - 1e-9) continue;
            const Eigen::VectorXd exact = ((-k.array() * r.dt).exp() * r.x_end.array()).matrix();
            const Eigen::VectorXd e = r.x_projected - exact;
            const std::vector<double> w = projection_weights(
                std::vector<SlopeNode>{{0.0, r.slope, r.slope_standard_error}}, 0.0, r.dt);
            for (Eigen::Index i = 0; i < dim; ++i) {
                out.jump_err.push_back(e[i]);
                out.jump_pred.push_back(w[0] * r.slope_standard_error[i]);
            }
            sum += e;
            charged += r.controller.statistical_nodes.cwiseAbs2();
            own += (w[0] * r.slope_standard_error).cwiseAbs2();
        }
        for (Eigen::Index i = 0; i < dim; ++i) {
            out.accumulated.push_back(sum[i]);
            out.charged_var.push_back(charged[i]);
            out.own_var.push_back(own[i]);
        }
    }
    return out;
}

double mean(const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return s / static_cast<double>(v.size());
}

}  // namespace

TEST_CASE("pooled jumps: each one's error shrinks, the run's accumulated error is what is charged",
          "[unit][coarse][slope_pool]") {
    // Fixed DT = 12 with bursts of 1 + 4 over 500 time units (~29 jumps), 10 seeds x 19
    // components. The sum of each run's true jump errors (its accumulated error, k DT ~ 1e-3:
    // undamped) has the variance the budget charged (sum of the charged variances), for one-burst
    // and pooled slopes alike; for pooled slopes the sum of the jumps' own variances misses the
    // correlation between jumps by about the pool size (4). 190 accumulated errors estimate a
    // variance to ~10 % (1 s.d.); the bounds are three of those. Per-jump errors: as in the
    // estimator test (~1/4, +-25 %).
    const PooledRun burst = pooled_run(SlopeSource::burst, 10);
    const PooledRun pooled = pooled_run(SlopeSource::pooled, 10);
    const double per_jump = mean_square(pooled.jump_err) / mean_square(burst.jump_err);
    const double per_jump_pred = mean_square(pooled.jump_pred) / mean_square(burst.jump_pred);
    INFO("per-jump variance pooled / burst: measured " << per_jump << ", predicted "
                                                       << per_jump_pred);
    CHECK(per_jump / per_jump_pred > 0.75);
    CHECK(per_jump / per_jump_pred < 1.33);
    CHECK(per_jump < 0.4);  // the jump's own error is halved or better

    const double burst_acc = mean_square(burst.accumulated) / mean(burst.charged_var);
    const double pooled_acc = mean_square(pooled.accumulated) / mean(pooled.charged_var);
    const double pooled_naive = mean_square(pooled.accumulated) / mean(pooled.own_var);
    INFO("accumulated variance / charged: one burst " << burst_acc << ", pooled " << pooled_acc
                                                      << "; pooled / own " << pooled_naive);
    CHECK(burst_acc > 0.7);
    CHECK(burst_acc < 1.4);
    CHECK(pooled_acc > 0.7);
    CHECK(pooled_acc < 1.4);
    CHECK(pooled_naive > 2.0);  // the sum of the jumps' own variances would claim too little
    // And the accumulated error itself is not smaller with pooled slopes (telescoping).
    const double acc_ratio = mean_square(pooled.accumulated) / mean_square(burst.accumulated);
    INFO("accumulated variance pooled / burst " << acc_ratio);
    CHECK(acc_ratio > 0.6);
}
