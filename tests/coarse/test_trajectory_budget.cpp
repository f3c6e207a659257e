// cpi.accuracy (coarse/equation_free/projective/trajectory_budget.hpp): the ensemble's standard
// error, each jump's tolerance from the trajectory's budget (closed form without contraction,
// more room with it, none once spent), the accumulated error a Monte Carlo of budgeted jumps
// ends with, and — through the integrator on a noisy SDE with a known mean — that the budget
// charged is the error the jumps made and a looser accuracy costs less DEM time.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/projective/multistep_projective_integrator.hpp"
#include "coarse/equation_free/projective/trajectory_budget.hpp"
#include "tests/coarse/toy_steppers.hpp"

using namespace efdem;
using namespace efdem::coarse;

namespace {

/// One forward-Euler node with slope standard error `se` on every one of `dim` components and
/// no curvature: a jump of DT has statistical error DT se, no truncation.
JumpErrorModel euler(double se, double t0, Eigen::Index dim = 4) {
    return {{SlopeNode{t0, Eigen::VectorXd::Zero(dim), Eigen::VectorXd::Constant(dim, se)}},
            t0,
            std::numeric_limits<double>::quiet_NaN(),
            1.0,
            {},
            {}};
}

}  // namespace

TEST_CASE("the ensemble's standard error is the RMS over components of sqrt(var / R)",
          "[unit][coarse][trajectory_budget]") {
    // Two members 2 apart on component 0 (unbiased variance 2), 4 apart on component 1 (8):
    // sqrt(mean(2, 8) / 2) = sqrt(2.5).
    Eigen::MatrixXd m(2, 2);
    m << 0.0, 0.0, 2.0, 4.0;
    CHECK(TrajectoryBudget::standard_error(m) == Approx(std::sqrt(2.5)).epsilon(1e-14));
    CHECK(std::isnan(TrajectoryBudget::standard_error(Eigen::MatrixXd::Ones(1, 3))));
}

TEST_CASE("a jump's tolerance spreads the budget over the jumps left, as the closed form says",
          "[unit][coarse][trajectory_budget]") {
    // No contraction, nothing spent: n = H / (DT + b) jumps of error DT se each accumulate to
    // sqrt(n) DT se = B, i.e. H se^2 DT^2 = B^2 (DT + b): DT from the quadratic, tolerance DT se.
    TrajectoryBudget b(2.0);
    b.measure(0.05);  // B = 0.1
    const double se = 0.002, h = 400.0, burst = 20.0, big = 1e4;
    const double bb = b.budget() * b.budget(), a = h * se * se;
    const double dt = (bb + std::sqrt(bb * bb + 4.0 * a * bb * burst)) / (2.0 * a);
    CHECK(b.jump_tolerance(euler(se, 100.0), 100.0 + h, burst, big) ==
          Approx(dt * se).epsilon(1e-5));
    // dt_max caps the jump, and so its tolerance.
    CHECK(b.jump_tolerance(euler(se, 100.0), 100.0 + h, burst, 10.0) ==
          Approx(10.0 * se).epsilon(1e-12));
    // Half the budget's variance spent leaves sqrt(1/2) of the room: DT from H se^2 DT^2 =
    // (B^2 / 2)(DT + b).
    b.commit(100.0, b.budget() / std::sqrt(2.0), 0.0);
    const double half = 0.5 * bb;
    const double dt_half = (half + std::sqrt(half * half + 4.0 * a * half * burst)) / (2.0 * a);
    CHECK(b.jump_tolerance(euler(se, 100.0), 100.0 + h, burst, big) ==
          Approx(dt_half * se).epsilon(1e-5));
    // All of it spent (a truncation error as large as the budget): no jump fits.
    b.commit(100.0, 0.0, b.budget());
    CHECK(b.jump_tolerance(euler(se, 100.0), 100.0 + h, burst, big) == 0.0);
}

TEST_CASE("the accumulated error contracts at the credited rate, earned by two bursts in a row",
          "[unit][coarse][trajectory_budget]") {
    TrajectoryBudget b(1.0);
    b.measure(1.0);
    CHECK(b.spent(5.0) == 0.0);  // nothing committed yet
    b.commit(10.0, 0.3, 0.1);
    CHECK(b.spent(10.0) == Approx(0.4).epsilon(1e-14));
    // One burst's decay earns nothing (a transient); a second resolved decay earns the smaller
    // of the two, at most the cap; a burst without one takes the credit away.
    b.credit(0.2, 0.1);
    CHECK(b.rate() == 0.0);
    b.credit(0.05, 0.1);
    CHECK(b.rate() == 0.05);
    CHECK(b.spent(30.0) == Approx(0.4 * std::exp(-1.0)).epsilon(1e-14));
    b.credit(0.3, 0.1);
    CHECK(b.rate() == 0.05);  // the smaller of the last two
    b.credit(0.3, 0.1);
    CHECK(b.rate() == 0.1);  // the cap
    b.credit(std::numeric_limits<double>::quiet_NaN(), 0.1);
    CHECK(b.rate() == 0.0);
    // A second jump adds its statistical part in quadrature to the contracted first.
    b.credit(0.05, 0.1);
    b.credit(0.05, 0.1);
    b.commit(30.0, 0.4, 0.0);
    const double e = std::exp(-1.0);
    CHECK(b.spent(30.0) == Approx(0.1 * e + std::sqrt(0.09 * e * e + 0.16)).epsilon(1e-14));
    // Contraction frees room for the next jump (the old errors have decayed), never promises
    // any for the future: at the same account, more time since the last jump, more room.
    const double se = 0.02;
    const double soon = b.jump_tolerance(euler(se, 30.0), 400.0, 20.0, 1e4);
    const double later = b.jump_tolerance(euler(se, 60.0), 430.0, 20.0, 1e4);
    CHECK(soon < 0.5);  // the budget, not the horizon, sets it
    CHECK(later > soon);
}

TEST_CASE("budgeted jumps end within the trajectory's budget",
          "[unit][coarse][trajectory_budget]") {
    // Monte Carlo of the budget's own model: each jump's error is normal with the standard
    // deviation its tolerance allows (DT se), jumps follow the plan until the run ends. The end
    // error's RMS over 4,000 runs (relative s.d. ~1.1 %) must lie within the budget (<= 1.03 B)
    // and use most of it (>= 0.8 B: the last cycle, shorter than a jump and burst, spends less).
    const double se = 0.002, burst = 20.0, t_end = 600.0;
    std::mt19937_64 rng(7);
    std::normal_distribution<double> normal;
    double sum2 = 0.0, budget = 0.0;
    const int runs = 4000;
    for (int run = 0; run < runs; ++run) {
        TrajectoryBudget b(1.5);
        b.measure(0.08);
        budget = b.budget();
        double t = 30.0, err = 0.0;
        while (t_end - t > burst) {
            const double tol = b.jump_tolerance(euler(se, t), t_end, burst, 200.0);
            const double dt = std::min(tol / se, t_end - t - burst);
            if (dt < 1.0) {  // below any dt_min: the rest runs directly
                t = t_end;
                break;
            }
            err += normal(rng) * dt * se;
            b.commit(t + dt, dt * se, 0.0);
            t += dt + burst;
        }
        sum2 += err * err;
    }
    const double rms = std::sqrt(sum2 / runs);
    INFO("end error RMS " << rms << " against the budget " << budget);
    CHECK(rms <= 1.03 * budget);
    CHECK(rms >= 0.8 * budget);
}

namespace {

/// Adaptive CPI with cpi.accuracy = `accuracy` on the OU toys below: bursts of healing 1 and
/// `window`, jumps of 2.5 to `dt_max` in steps of 0.1.
MultistepSettings budgeted(double accuracy, double window, double dt_max) {
    MultistepSettings s;
    s.burst.healing = 1.0;
    s.burst.window = window;
    s.control = {.tolerance = 1.0, .dt_min = 2.5, .dt_max = dt_max};
    s.dt_quantum = 0.1;
    s.accuracy = accuracy;
    return s;
}

struct BudgetRun {
    std::vector<double> accumulated;  ///< per seed and component: the sum of the jumps' errors
    std::vector<double> spent;        ///< per seed: the budget's account of it at the end
    std::vector<double> walk;         ///< per seed: the walk's share of that account (variance)
    double max_spent_over_budget = 0.0;
    double work = 0.0;  ///< micro time run, all seeds
    long jumps = 0;
};

/// Adaptive CPI with cpi.accuracy = a on an ensemble of 8 slow Ornstein-Uhlenbeck processes
/// (k = 1e-4: the mean barely moves, the members' spread grows as a random walk), bursts 1 + 4,
/// 300 time units.
BudgetRun budget_run(double a, std::uint64_t seeds) {
    const Eigen::Index dim = 19;
    const Eigen::VectorXd k = Eigen::VectorXd::Constant(dim, 1e-4);
    BudgetRun out;
    for (std::uint64_t seed = 1; seed <= seeds; ++seed) {
        test::OuEnsembleStepper toy(k, 0.05, 8, 0.1, Eigen::VectorXd::Constant(dim, 3.0),
                                    300 + seed);
        MultistepProjectiveIntegrator integrator(budgeted(a, 4.0, 80.0));
        integrator.set_end_time(300.0);
        Eigen::VectorXd sum = Eigen::VectorXd::Zero(dim);
        double spent = 0.0, walk = 0.0;
        while (300.0 - toy.time() >= 5.0 - 1e-9) {
            const ProjectiveStepRecord r = integrator.step(toy);
            REQUIRE(r.advanced());
            const ControllerRecord& c = r.controller;
            if (std::isfinite(c.budget_spent)) {
                spent = c.budget_spent;
                out.max_spent_over_budget = std::max(out.max_spent_over_budget, spent / c.budget);
            }
            if (r.status != StepStatus::projected) continue;
            ++out.jumps;
            if (std::isfinite(c.budget_walk)) walk += c.budget_walk * c.budget_walk;
            const Eigen::VectorXd exact = ((-k.array() * r.dt).exp() * r.x_end.array()).matrix();
            sum += r.x_projected - exact;
        }
        for (Eigen::Index i = 0; i < dim; ++i) out.accumulated.push_back(sum[i]);
        out.spent.push_back(spent);
        out.walk.push_back(walk);
        out.work += toy.work();
    }
    return out;
}

}  // namespace

TEST_CASE("cpi.accuracy: the budget charged is the error the jumps made, a looser one costs less",
          "[unit][coarse][trajectory_budget]") {
    // 12 seeds x 19 components. The accumulated true jump error's mean square (each jump's
    // DT (s - exact slope): its slope's error alone) against the mean of the budget's account
    // of it (spent^2 less the walk it was charged beyond the slopes, which the next test checks;
    // no truncation resolves at k = 1e-4): 228 values estimate a variance to ~10 % (1 s.d.), the
    // components of one seed share their jumps' DT, so the bounds are wide (0.6-1.6). The account
    // never exceeds the budget by more than a kept jump's a posteriori excess (5 %).
    const BudgetRun tight = budget_run(3.0, 12);
    const BudgetRun loose = budget_run(8.0, 12);
    for (const BudgetRun* run : {&tight, &loose}) {
        double acc = 0.0, charged = 0.0;
        for (double e : run->accumulated) acc += e * e;
        acc /= static_cast<double>(run->accumulated.size());
        for (std::size_t i = 0; i < run->spent.size(); ++i)
            charged += run->spent[i] * run->spent[i] - run->walk[i];
        charged /= static_cast<double>(run->spent.size());
        INFO("jumps " << run->jumps << ", accumulated mean square " << acc << ", charged "
                      << charged << ", max spent / budget " << run->max_spent_over_budget);
        CHECK(run->jumps > 12);  // at least one jump per seed on average
        CHECK(run->max_spent_over_budget <= 1.05);
        CHECK(acc / charged > 0.6);
        CHECK(acc / charged < 1.6);
    }
    INFO("DEM time: accuracy 3 " << tight.work << ", accuracy 8 " << loose.work);
    CHECK(loose.work < 0.9 * tight.work);
}

TEST_CASE("cpi.accuracy with cpi.jump_until plans the budget over the jumps before T",
          "[unit][coarse][trajectory_budget]") {
    // The budget is spread over the jumps still to come; with cpi.jump_until = T none comes after
    // T, so a 300-unit run with jumps until 100 must give its first budgeted jump the tolerance of
    // a run that ends at 100 (the same seed: the same bursts up to it, bit for bit), and a larger
    // one than a run that jumps to 300 (three times as many jumps share the budget there).
    const auto first_tolerance = [](double end_time, double jump_end) {
        const Eigen::Index dim = 19;
        test::OuEnsembleStepper toy(Eigen::VectorXd::Constant(dim, 1e-4), 0.05, 8, 0.1,
                                    Eigen::VectorXd::Constant(dim, 3.0), 301);
        MultistepProjectiveIntegrator integrator(budgeted(2.0, 4.0, 80.0));
        integrator.set_end_time(end_time);
        integrator.set_jump_end(jump_end);
        while (toy.time() < 50.0) {
            const ProjectiveStepRecord r = integrator.step(toy);
            REQUIRE(r.advanced());
            if (std::isfinite(r.controller.budget) && std::isfinite(r.controller.tolerance))
                return r.controller.tolerance;
        }
        FAIL("no budgeted step before t = 50");
        return 0.0;
    };
    const double inf = std::numeric_limits<double>::infinity();
    const double until100 = first_tolerance(300.0, 100.0);
    CHECK(until100 == first_tolerance(100.0, inf));
    CHECK(until100 > 1.2 * first_tolerance(300.0, inf));
}

TEST_CASE("a jump is charged the walk it carries and the walk it skips",
          "[unit][coarse][trajectory_budget]") {
    // walk_rate: q / R = W se^2 / 1.2 (the least-squares slope of a walk over W), W se^2 for the
    // increment.
    const SlopeNode node{0.0, Eigen::VectorXd::Zero(3), Eigen::Vector3d(0.01, 0.02, 0.02)};
    CHECK(walk_rate(node, 12.0, SlopeFit::least_squares) ==
          Approx(12.0 * (1e-4 + 4e-4 + 4e-4) / 3.0 / 1.2).epsilon(1e-14));
    CHECK(walk_rate(node, 12.0, SlopeFit::increment) ==
          Approx(12.0 * (1e-4 + 4e-4 + 4e-4) / 3.0).epsilon(1e-14));
    CHECK(walk_rate(node, 0.0, SlopeFit::increment) == 0.0);
    // The plan: n = H / (DT + b) jumps of variance se^2 DT^2 + w DT reach B^2:
    // H se^2 DT^2 + (w H - B^2) DT - B^2 b = 0.
    TrajectoryBudget b(2.0);
    b.measure(0.05);  // B = 0.1
    const double se = 0.002, h = 400.0, burst = 20.0, w = 2e-5;
    const double bb = b.budget() * b.budget(), a = h * se * se, lin = w * h - bb;
    const double dt = (-lin + std::sqrt(lin * lin + 4.0 * a * bb * burst)) / (2.0 * a);
    CHECK(b.jump_tolerance(euler(se, 100.0), 100.0 + h, burst, 1e4, w) ==
          Approx(dt * se).epsilon(1e-5));
    CHECK(b.jump_tolerance(euler(se, 100.0), 100.0 + h, burst, 1e4, w) <
          b.jump_tolerance(euler(se, 100.0), 100.0 + h, burst, 1e4));
    // The account: a kept jump adds its slope's variance and its walk.
    b.commit(110.0, 0.03, 0.0, 0.0016);
    CHECK(b.spent(110.0) == Approx(std::sqrt(0.0009 + 0.0016)).epsilon(1e-14));
}

TEST_CASE("cpi.accuracy charges what the jumps add to the error beyond a direct ensemble's",
          "[unit][coarse][trajectory_budget]") {
    // 48 seeds x 19 components of 8 slow OU members (k = 1e-4, sigma = 0.05: a walk over 300
    // units), bursts 1 + 10, jumps of at most 12 (a loose accuracy: most jumps are 12, where the
    // walk term DT q / R is W / (1.2 DT) = 0.7 of the slope's variance). The CPI mean's squared
    // error at the end against the exact mean, less a direct ensemble's own (the members' OU
    // variance / 8), is what the jumps added; its mean against the mean of the budget's account
    // (spent^2: no truncation resolves, the toy's lift is exact). 912 values estimate the mean
    // square to ~5 %, about 8 % of the excess (1 s.d.); the bounds 0.7-1.3 are ~4 s.d. (0.89
    // when written). Without the walk term the account would be 1 / 1.69 of itself here (the
    // ratio ~1.5, outside). The same with cpi.slope_fit = increment, whose slope has 1/1.2 of the
    // variance and whose walk rate is therefore read as W se^2 (0.94 when written; with least
    // squares' 1.2 the walk would be charged 1/1.2 of itself). That bound is wide; the walk
    // each jump was charged, budget_walk^2 / DT, is checked directly against the toy's q / R =
    // sigma^2 / 8: each jump's reading scatters by about 12 % (8 members' spread, 19
    // components), so the mean over ~640 jumps by 0.5 %; the bound 5 % holds the discrete
    // least-squares factor (101 samples: 1.19, not 1.2) and the OU's slight relaxation, and a
    // factor of the wrong fit (17 % off) fails it.
    const SlopeFit fit = GENERATE(SlopeFit::least_squares, SlopeFit::increment);
    const Eigen::Index dim = 19;
    const double k = 1e-4, sigma = 0.05, x0 = 3.0;
    const int members = 8;
    double excess = 0.0, charged = 0.0, walk = 0.0;
    long values = 0, jumps = 0, walks = 0;
    for (std::uint64_t seed = 1; seed <= 48; ++seed) {
        test::OuEnsembleStepper toy(Eigen::VectorXd::Constant(dim, k), sigma, members, 0.1,
                                    Eigen::VectorXd::Constant(dim, x0), 700 + seed);
        MultistepSettings settings = budgeted(50.0, 10.0, 12.0);
        settings.slope_fit = fit;
        MultistepProjectiveIntegrator integrator(settings);
        integrator.set_end_time(300.0);
        double spent = 0.0;
        while (300.0 - toy.time() >= 11.0 - 1e-9) {
            const ProjectiveStepRecord r = integrator.step(toy);
            REQUIRE(r.advanced());
            if (std::isfinite(r.controller.budget_spent)) spent = r.controller.budget_spent;
            if (r.status == StepStatus::projected) ++jumps;
            if (r.status == StepStatus::projected && std::isfinite(r.controller.budget_walk)) {
                walk += r.controller.budget_walk * r.controller.budget_walk / r.dt;
                ++walks;
            }
        }
        const double t = toy.time();
        const double exact = x0 * std::exp(-k * t);
        const double direct = sigma * sigma * (1.0 - std::exp(-2.0 * k * t)) / (2.0 * k) / members;
        const Eigen::VectorXd m = toy.mean();
        for (Eigen::Index i = 0; i < dim; ++i, ++values)
            excess += (m[i] - exact) * (m[i] - exact) - direct;
        charged += spent * spent * static_cast<double>(dim);
    }
    excess /= static_cast<double>(values);
    charged /= static_cast<double>(values);
    INFO("fit " << static_cast<int>(fit) << ": jumps " << jumps << ", excess " << excess
                << ", charged " << charged);
    CHECK(jumps > 48 * 10);
    CHECK(excess / charged > 0.7);
    CHECK(excess / charged < 1.3);
    REQUIRE(walks > 48 * 10);
    CHECK(walk / static_cast<double>(walks) / (sigma * sigma / members) ==
          Approx(1.0).epsilon(0.05));
}
