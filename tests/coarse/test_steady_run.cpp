// The run loop of mode = steady | continuation (coarse/equation_free/steady/steady_run.hpp) on toy
// steppers, without DEM or MPI: warm-up, solve, spectrum, observers, the budget stop, the
// repair count, and continuation in a scaled parameter reported in the scene's units.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Core>

#include "coarse/demixing/icdf_gap_coordinates.hpp"
#include "coarse/equation_free/steady/steady_run.hpp"
#include "tests/coarse/steady_toy_steppers.hpp"

using namespace efdem;
using namespace efdem::coarse;

namespace {
/// x' = -0.1 (x - x*) in two components, exactly per interval 0.5: Phi_tau(X) = x* + e^{-0.1 tau}(X
/// - x*).
test::AffineToyStepper decaying(const Eigen::Vector2d& x_star) {
    return {std::exp(-0.1 * 0.5) * Eigen::Matrix2d::Identity(), x_star, 0.5};
}

SteadyRunSettings newton_settings() {
    SteadyRunSettings s;
    s.warmup = 1.0;
    s.map.tau = 4.0;
    s.map.difference_step = 1e-6;
    s.newton.stop.tolerance = 1e-10;
    s.eigenvalues = 2;
    s.spectrum.eigenvalues = 2;
    s.spectrum.tolerance = 1e-8;
    return s;
}
}  // namespace

TEST_CASE("SteadyRun: warm-up, Newton solve and spectrum; every iterate observed",
          "[unit][steady]") {
    const Eigen::Vector2d x_star(3.0, 5.0);
    test::AffineToyStepper toy = decaying(x_star);
    toy.lift(Eigen::Vector2d(0.0, 0.0), 0.0);
    SteadyRun run(newton_settings(), toy, {});
    long seen = 0;
    run.set_iterate_observer([&](const SteadySolveRecord& rec) {
        ++seen;
        CHECK(static_cast<long>(rec.residuals.size()) == seen);  // one call per iterate, in order
        return std::string{};
    });
    const SteadyRunOutcome out = run.run();
    REQUIRE(out.converged);
    CHECK(out.end_status.rfind("completed", 0) == 0);
    // The initial guess is the warm-up's last sample: x* + e^{-0.1}(0 - x*).
    CHECK((out.x0 - x_star * (1.0 - std::exp(-0.1))).norm() < 1e-12);
    // An affine F: the answer within |J_F^-1| x 1e-10 = 1e-10 / (1 - e^{-0.4}) ~ 3e-10.
    CHECK((out.solve.x - x_star).norm() < 1e-9);
    CHECK(seen == static_cast<long>(out.solve.residuals.size()));
    REQUIRE(out.spectrum.leading.size() == 2);
    // Both eigenvalues are e^{-0.1 tau}; the rate log|mu|/tau recovers -0.1 (1e-7: the
    // differences' round-off eps |X| / h ~ 1e-9, divided by mu tau).
    for (const CoarseEigenvalue& e : out.spectrum.leading)
        CHECK(e.rate == Approx(-0.1).margin(1e-6));
    CHECK(out.micro_time == Approx(out.tau * static_cast<double>(out.evaluations)).epsilon(1e-14));
}

TEST_CASE("SteadyRun: an observer's stop ends the solve unconverged with the best iterate kept",
          "[unit][steady]") {
    const Eigen::Vector2d x_star(3.0, 5.0);
    test::AffineToyStepper toy = decaying(x_star);
    SteadyRunSettings s = newton_settings();
    s.solver = SteadyRunSettings::Solver::anderson;
    s.map.common_random_numbers = false;
    s.fixed_point.stop.tolerance = 1e-12;
    s.fixed_point.depth = 0;  // damped iteration: |F| falls by e^{-0.4} = 0.67 per iteration
    s.eigenvalues = 0;
    toy.lift(Eigen::Vector2d(0.0, 0.0), 0.0);  // away from x*
    SteadyRun run(s, toy, {});
    run.set_iterate_observer([](const SteadySolveRecord& rec) {
        return rec.residuals.size() >= 3 ? std::string("budget spent") : std::string{};
    });
    const SteadyRunOutcome out = run.run();
    CHECK_FALSE(out.converged);
    CHECK(out.solve.reason == SteadyStopReason::stopped);
    CHECK(out.solve.message.find("budget spent") != std::string::npos);
    CHECK(out.end_status.rfind("not converged", 0) == 0);
    REQUIRE(out.solve.residuals.size() == 3);
    // Plain iteration contracts: the best iterate is the last one, and it is saved.
    CHECK(out.solve.best_residual == out.solve.residuals.back());
    CHECK((out.solve.best - out.solve.x).norm() == 0.0);
    CHECK(out.spectrum.leading.empty());
}

TEST_CASE("SteadyRun: the repair hook is applied to every lifted point and its changes are counted",
          "[unit][steady]") {
    const Eigen::Vector2d x_star(3.0, 5.0);
    test::AffineToyStepper toy = decaying(x_star);
    SteadyRunSettings s = newton_settings();
    s.eigenvalues = 0;
    s.newton.max_iterations = 1;
    // Clip the second component at 4.5: the fixed point (5) lies outside, so every lift near
    // it is changed; F is then that of the clipped point and Newton cannot reach x*.
    long calls = 0;
    RepairHook clip = [&calls](Eigen::VectorXd& x) {
        ++calls;
        RepairReport r;
        if (x[1] > 4.5) {
            r.max_adjustment = x[1] - 4.5;
            x[1] = 4.5;
        }
        return r;
    };
    toy.lift(Eigen::Vector2d(3.0, 5.0), 0.0);  // the warm-up starts at x*: X0 = x*
    SteadyRun run(s, toy, clip);
    const SteadyRunOutcome out = run.run();
    CHECK(calls == out.evaluations);
    CHECK(out.repairs >= 1);
    CHECK(out.largest_repair == Approx(0.5).margin(1e-6));
}

TEST_CASE("SteadyRun: continuation in a scaled parameter reports the branch in the scene's units",
          "[unit][steady]") {
    // x' = lambda - x (one member, no noise): the steady state is x = lambda, stable with
    // mu = e^{-tau}. Continued from 0.2 to 0.6 in lambda / 0.1.
    test::SdeEnsembleStepper toy(
        [](const Eigen::VectorXd& x, double lambda) -> Eigen::VectorXd {
            return Eigen::VectorXd::Constant(x.size(), lambda) - x;
        },
        0.0, 1, 0.01, 10, Eigen::VectorXd::Zero(1), 1);
    SteadyRunSettings s = newton_settings();
    s.continuation = true;
    s.map.tau = 1.0;
    s.warmup = 0.1;
    s.parameter = "lambda";
    s.parameter_start = 0.2;
    s.parameter_end = 0.6;
    s.parameter_scale = 0.1;
    s.branch.corrector = s.newton;
    s.branch.parameter_step = 0.1 / 0.1;  // 0.1 in lambda
    s.branch.step = 1.0;
    s.branch.min_step = 0.01;
    s.branch.max_step = 2.0;
    s.branch.max_parameter_step = 0.1 / 0.1;  // at most 0.1 per point: 0.2, 0.3, ..., 0.6
    s.branch.parameter_min = 0.2 / 0.1;
    s.branch.parameter_max = 0.6 / 0.1;
    s.branch.display_scale = 0.1;
    s.branch.spectrum.eigenvalues = 1;
    double set_to = -1;
    SteadyRun run(s, toy, {}, [&](double v) {
        set_to = v;
        toy.set_parameter(v);
    });
    long points_seen = 0;
    run.set_point_observer([&](const Branch& b) {
        ++points_seen;
        CHECK(b.points.back().parameter ==
              Approx(b.points.back().x[0]).margin(1e-7));  // scene units
    });
    const SteadyRunOutcome out = run.run();
    INFO(out.branch.end_reason);
    REQUIRE(out.converged);
    // The corrector converges in one step on this linear branch, which would double the step
    // every point (0.2, 0.3, 0.5, 0.9); the cap keeps 0.1 and the last predictor lands on 0.6.
    REQUIRE(out.branch.points.size() == 5);
    CHECK(points_seen == static_cast<long>(out.branch.points.size()));
    for (std::size_t k = 0; k < out.branch.points.size(); ++k)
        CHECK(out.branch.points[k].parameter ==
              Approx(0.2 + 0.1 * static_cast<double>(k)).margin(1e-9));
    CHECK(out.branch.end_reason.find("reached the end of the parameter range [0.2, 0.6] at 0.6") !=
          std::string::npos);
    for (const BranchPoint& p : out.branch.points) {
        // The corrector stops at |G| <= 1e-10 with a well-conditioned extended Jacobian.
        CHECK(p.x[0] == Approx(p.parameter).margin(1e-7));
        REQUIRE(p.has_leading);
        // mu = R(-dt)^(tau/dt) with R the RK4 polynomial = e^{-1} to O(tau dt^4) ~ 1e-9.
        CHECK(p.leading.mu.real() == Approx(std::exp(-1.0)).margin(1e-6));
    }
    CHECK(set_to > 0.55);  // the hook saw scene units, not lambda / 0.1
}

TEST_CASE(
    "gap coordinates: every lifted point is an increasing ICDF, the answer is reported in heights",
    "[unit][steady]") {
    const CoarseCoordinates gaps = icdf_gap_coordinates();
    const Eigen::Vector3d x(1.0, 1.5, 4.0);
    // u = (1, log 0.5, log 2.5); back to x to round-off.
    const Eigen::VectorXd u = gaps.from_state(x);
    CHECK(u[1] == Approx(std::log(0.5)).epsilon(1e-14));
    CHECK((gaps.to_state(u) - x).norm() < 1e-14);
    // Any u is increasing (while exp(u_i) is above the round-off of the heights).
    const Eigen::VectorXd wild = gaps.to_state(Eigen::Vector3d(-3.0, 5.0, -10.0));
    CHECK((wild[1] > wild[0] && wild[2] > wild[1]));

    // x' = -0.1 (x - x*) with x* increasing; Newton in u (F is not affine in u: two or three
    // steps) from an increasing start.
    const Eigen::Vector3d x_star(1.0, 2.0, 4.0);
    test::AffineToyStepper toy({std::exp(-0.1 * 0.5) * Eigen::Matrix3d::Identity(), x_star, 0.5});
    toy.lift(Eigen::Vector3d(0.0, 0.2, 0.5), 0.0);
    SteadyRunSettings s = newton_settings();
    s.eigenvalues = 1;
    s.spectrum.eigenvalues = 1;
    long non_monotone = 0, lifts = 0;
    RepairHook check = [&](Eigen::VectorXd& v) {
        ++lifts;
        for (Eigen::Index i = 1; i < v.size(); ++i)
            if (!(v[i] > v[i - 1])) ++non_monotone;
        return RepairReport{};
    };
    SteadyRun run(s, toy, check, {}, gaps);
    // What is recorded of every iterate is in heights: the observer sees X (not u), and the
    // state residual is |Phi(X) - X| = (1 - e^{-0.1 tau}) |X - x*| exactly for this map, while
    // the solver's own residual is in log gaps (at the start here 0.84 of it: another number).
    const double contraction = 1.0 - std::exp(-0.1 * s.map.tau);
    long observed = 0;
    double worst = 0.0, first_ratio = 0.0;
    run.set_iterate_observer([&](const SteadySolveRecord& rec) {
        const double expected = contraction * (rec.x - Eigen::VectorXd(x_star)).norm();
        worst =
            std::max(worst, std::abs(rec.state_residuals.back() - expected) / (expected + 1e-12));
        if (observed++ == 0) first_ratio = rec.residuals.back() / rec.state_residuals.back();
        return std::string{};
    });
    const SteadyRunOutcome out = run.run();
    INFO(out.end_status);
    REQUIRE(out.converged);
    REQUIRE(observed >= 2);
    // Round-off of the heights (~1e-15) against |F| down to ~1e-11 at the last iterate, with
    // 1e-12 d_p absolute added: 1e-3 relative leaves a decade over what is seen (2e-4).
    CHECK(worst < 1e-3);
    CHECK(std::abs(first_ratio - 1.0) > 0.05);
    CHECK(out.coordinates == "gaps");
    CHECK(lifts == out.evaluations);
    CHECK(non_monotone == 0);
    // |F| <= 1e-10 in u; u -> X is Lipschitz with constant max(1, gaps) ~ 2 here.
    CHECK((out.solve.x - x_star).norm() < 1e-8);
    CHECK((out.solve.best - x_star).norm() < 1e-8);
    // The eigenvalue is coordinate-free at the fixed point: e^{-0.1 tau}.
    REQUIRE(out.spectrum.leading.size() == 1);
    CHECK(out.spectrum.leading.front().rate == Approx(-0.1).margin(1e-5));
}

TEST_CASE("SteadyRun: without steady.difference_step, h is 6 x the noise at the end of the warm-up",
          "[unit][steady]") {
    // Three independent Ornstein-Uhlenbeck components dY = -k (Y - c) dt + sigma dW in 64
    // members, all started at c: after the warm-up T a member's variance is
    // sigma^2 (1 - e^{-2kT}) / 2k, so the noise norm of the mean is known in closed form.
    const Eigen::Vector3d k(0.5, 1.0, 2.0), c(1.0, -2.0, 3.0);
    constexpr double kSigma = 0.1, kWarmup = 4.0;
    constexpr int kMembers = 64;
    auto drift = [k, c](const Eigen::VectorXd& y, double) -> Eigen::VectorXd {
        return (-k.array() * (y - c).array()).matrix();
    };
    SteadyRunSettings s = newton_settings();
    s.warmup = kWarmup;
    s.map.tau = 2.0;
    s.map.common_random_numbers = true;
    s.map.difference_step = 0.5;  // what the scene's default would be
    s.difference_step_from_noise = true;
    s.newton.max_iterations = 2;
    s.eigenvalues = 0;
    double expected2 = 0;
    for (int i = 0; i < 3; ++i)
        expected2 +=
            kSigma * kSigma * (1.0 - std::exp(-2.0 * k[i] * kWarmup)) / (2.0 * k[i]) / kMembers;
    const double expected = std::sqrt(expected2);  // 0.0164

    SECTION("derived from the members' spread") {
        test::SdeEnsembleStepper toy(drift, kSigma, kMembers, 0.05, 10, c, 3);
        const SteadyRunOutcome out = SteadyRun(s, toy, {}).run();
        // The sample variance of 64 members has 63 degrees of freedom: ~9 % relative spread
        // per component, ~5 % in the norm over three; 25 % is five of those.
        CHECK(out.difference_step == Approx(s.difference_noise_multiple * expected).epsilon(0.25));
        CHECK(out.difference_step_origin.find("x the noise norm") != std::string::npos);
        // Exactly what the same warm-up's members give (the same seed).
        test::SdeEnsembleStepper twin(drift, kSigma, kMembers, 0.05, 10, c, 3);
        BurstSamples warm;
        twin.run(kWarmup, warm);
        const Eigen::MatrixXd& m = warm.members.back();
        const Eigen::VectorXd mean = m.colwise().mean().transpose();
        double se2 = 0;
        for (Eigen::Index i = 0; i < m.cols(); ++i)
            se2 += (m.col(i).array() - mean[i]).square().sum() / (kMembers - 1) / kMembers;
        CHECK(out.difference_step ==
              Approx(s.difference_noise_multiple * std::sqrt(se2)).epsilon(1e-12));
    }
    SECTION("more than the map's curvature allows: capped at a quarter of |X|, with a warning") {
        s.difference_noise_multiple = 1e4;  // ~160, against |X| = |(1, -2, 3)| = 3.7
        test::SdeEnsembleStepper toy(drift, kSigma, kMembers, 0.05, 10, c, 3);
        const SteadyRunOutcome out = SteadyRun(s, toy, {}).run();
        CHECK(out.difference_step == Approx(0.25 * out.x0.norm()).epsilon(1e-12));
        CHECK(out.difference_step_origin.find("capped at") != std::string::npos);
    }
    SECTION("set in the scene: used as it is") {
        s.difference_step_from_noise = false;
        test::SdeEnsembleStepper toy(drift, kSigma, kMembers, 0.05, 10, c, 3);
        const SteadyRunOutcome out = SteadyRun(s, toy, {}).run();
        CHECK(out.difference_step == 0.5);
        CHECK(out.difference_step_origin == "steady.difference_step");
    }
    SECTION("one member: no spread to measure, the default") {
        test::SdeEnsembleStepper toy(drift, kSigma, 1, 0.05, 10, c, 3);
        const SteadyRunOutcome out = SteadyRun(s, toy, {}).run();
        CHECK(out.difference_step == 0.5);
        CHECK(out.difference_step_origin.find("fewer than two realizations") != std::string::npos);
    }
}
