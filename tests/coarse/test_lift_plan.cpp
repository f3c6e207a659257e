// The count plan of a lift (lift_plan.hpp): where a target's light counts that some interval
// cannot hold go. CountPlan::nearest against a brute-force enumeration of every feasible plan,
// and the segregated bed that CountPlan::halves mixes. Interval bookkeeping is done here
// independently (plain counting).
#include <catch2/catch.hpp>

#include <algorithm>
#include <functional>
#include <limits>
#include <numeric>
#include <utility>
#include <vector>

#include "coarse/demixing/colour_lifting.hpp"
#include "coarse/demixing/lift_plan.hpp"
#include "coarse/demixing/quantiles.hpp"
#include "core/rng.hpp"

using namespace efdem::coarse;
using Count = std::int64_t;

namespace {

using Miss = std::pair<Count, Count>;

/// Over the cuts: (sum |below - wanted|, sum (below - wanted)^2), compared in that order.
Miss miss(const std::vector<Count>& below, const std::vector<Count>& wanted) {
    Miss m{0, 0};
    for (std::size_t j = 0; j < below.size(); ++j) {
        const Count d = below[j] - wanted[j];
        m.first += std::abs(d);
        m.second += d * d;
    }
    return m;
}

/// The least miss over every feasible plan (0 = B_0 <= ... <= B_{m+1} = N_L, interval k holding
/// at most population[k]), by enumeration.
Miss brute_force_least(const std::vector<Count>& wanted, const std::vector<Count>& population) {
    const std::size_t n = wanted.size();
    const Count n_light = wanted.back();
    std::vector<Count> b(n, 0);
    b[n - 1] = n_light;
    Miss best{std::numeric_limits<Count>::max(), 0};
    std::function<void(std::size_t)> walk = [&](std::size_t j) {
        if (j == n - 1) {
            const Count step = n_light - b[j - 1];
            if (step >= 0 && step <= population[j - 1]) best = std::min(best, miss(b, wanted));
            return;
        }
        for (Count v = b[j - 1]; v <= std::min(n_light, b[j - 1] + population[j - 1]); ++v) {
            b[j] = v;
            walk(j + 1);
        }
    };
    walk(1);
    return best;
}

bool feasible(const LiftPlan& plan) {
    if (plan.below.front() != 0 || plan.below.back() != plan.n_observed) return false;
    for (std::size_t k = 0; k + 1 < plan.below.size(); ++k) {
        const Count step = plan.below[k + 1] - plan.below[k];
        if (step < 0 || step > plan.population[k]) return false;
    }
    return true;
}

}  // namespace

TEST_CASE("nearest counts: the feasible plan nearest the target's, against every plan",
          "[unit][coarse]") {
    // 300 small beds (12-30 particles, m = 5 cuts) with targets squeezed into random narrow
    // bands, most of them infeasible: the plan is feasible and its miss (lights placed across a
    // cut other than asked, then their squares) equals the least over every feasible plan,
    // enumerated. The old split (halves) is feasible too, never better,
    // and worse on some beds (else the new plan would change nothing).
    const ProbabilityGrid grid(5);
    efdem::RandomStream rng(71, 0, "test-lift-plan");
    int infeasible = 0, halves_worse = 0;
    for (int trial = 0; trial < 300; ++trial) {
        const auto n = static_cast<std::size_t>(12 + trial % 19);
        std::vector<double> z(n);
        std::vector<std::uint8_t> colour(n, kHeavy);
        for (std::size_t j = 0; j < n; ++j) {
            z[j] = rng.uniform(0.0, 10.0);
            colour[j] = rng.uniform() < 0.4 ? kLight : kHeavy;
        }
        colour[0] = kLight;
        const double from = rng.uniform(0.0, 9.0), width = rng.uniform(0.0, 3.0);
        Eigen::VectorXd target(grid.size());
        for (int i = 0; i < grid.size(); ++i) target[i] = from + width * (i + rng.uniform()) / 5.0;
        std::sort(target.data(), target.data() + target.size());
        const LiftPlan nearest = plan_lift(target, z, colour, grid, CountPlan::nearest);
        const LiftPlan halves = plan_lift(target, z, colour, grid, CountPlan::halves);
        REQUIRE(nearest.error.empty());
        INFO("trial " << trial);
        REQUIRE(feasible(nearest));
        REQUIRE(feasible(halves));
        const Miss least = brute_force_least(nearest.wanted, nearest.population);
        CHECK(miss(nearest.below, nearest.wanted) == least);
        CHECK(miss(halves.below, halves.wanted) >= least);
        if (nearest.wanted != nearest.below) ++infeasible;
        if (miss(halves.below, halves.wanted) > least) ++halves_worse;
        if (nearest.wanted == nearest.below) CHECK(halves.below == halves.wanted);
    }
    CHECK(infeasible > 100);
    CHECK(halves_worse > 10);
}

TEST_CASE("nearest counts: a segregated bed is not mixed to place a short interval's excess",
          "[unit][coarse]") {
    // 2,000 particles, the 1,000 highest light: fully segregated, as the tall bed is at
    // U_s = 0.41 (every particle above the light-heavy interface is light). The target is the
    // bed's own ICDF with the top node lowered into the run of lights, so the interval below it
    // holds fewer particles than the 50 lights it asks for. Its excess fits only above the
    // lowered cut (there the bed has room); below, every interval is full. The nearest plan puts
    // it there and changes no label: every other node stays exactly where it is. The halves
    // split hands half the excess down through all 18 full intervals into the heavy particles
    // (a lift that mixes the bed): measured on the tall bed's states this moved every node
    // 0.3-0.5 d_p down (docs/accuracy_vs_cost.md, "The count plan").
    efdem::RandomStream rng(72, 0, "test-lift-plan");
    const ProbabilityGrid grid;
    const std::size_t n = 2000;
    std::vector<double> z(n);
    for (double& h : z) h = rng.uniform(0.5, 50.0);
    std::vector<double> sorted = z;
    std::sort(sorted.begin(), sorted.end());
    const double interface = sorted[n / 2];
    std::vector<std::uint8_t> colour(n);
    for (std::size_t j = 0; j < n; ++j) colour[j] = z[j] >= interface ? kLight : kHeavy;
    const Eigen::VectorXd own = observed_icdf(z, colour, grid);
    Eigen::VectorXd target = own;
    target[18] = own[18] - 0.5;  // ~20 particles of the 50 between cuts 17 and 18 now above it
    REQUIRE(target[18] > own[17]);

    efdem::RandomStream a(73, 0, "lifting"), b(73, 0, "lifting");
    const LiftResult nearest = lift_colours(target, z, colour, grid, a);  // at_nodes: nearest
    const LiftResult halves = lift_colours(target, z, colour, grid, b, {}, Relabel::random);
    INFO(nearest.message);
    REQUIRE(nearest.n_short_intervals == 1);
    CHECK(nearest.n_changed == 0);
    for (int i = 0; i < 18; ++i) CHECK(nearest.achieved_icdf[i] == own[i]);
    // The halves plan mixes: labels change at the interface and the lower nodes move down by
    // about half the excess (~10 lights of 1,000: 0.25 d_p at 0.025 d_p per particle).
    CHECK(halves.n_changed >= 10);
    for (int i = 0; i < 17; ++i) CHECK(halves.achieved_icdf[i] < own[i] - 0.1);
}
