#include "coarse/demixing/lift_plan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "coarse/demixing/quantiles.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

using Count = std::int64_t;

/// The bounds of a feasible observed count below each cut j (m + 2 of them) for `n_light`
/// observed particles in intervals of `population`: L_j = max(0, N_L - (N - S_j)) <= B_j <= U_j =
/// min(N_L, S_j), S_j = particles below cut j (the others must fit above it, and no more than
/// S_j fit below).
struct CountBounds {
    std::vector<Count> lo, hi;
};

CountBounds count_bounds(Count n_light, const std::vector<Count>& population) {
    const std::size_t n_bounds = population.size() + 1;
    std::vector<Count> below(n_bounds, 0);
    for (std::size_t j = 1; j < n_bounds; ++j) below[j] = below[j - 1] + population[j - 1];
    const Count total = below.back();
    CountBounds b{std::vector<Count>(n_bounds), std::vector<Count>(n_bounds)};
    for (std::size_t j = 0; j < n_bounds; ++j) {
        b.lo[j] = std::max<Count>(0, n_light - (total - below[j]));
        b.hi[j] = std::min<Count>(n_light, below[j]);
    }
    return b;
}

/**
 * Observed counts below each cut: `wanted` (B_0 = 0, ..., B_{m+1} = N_L) made feasible for
 * interval populations `population` (0 <= B_{k+1} - B_k <= P_k, within count_bounds). A
 * forward pass pushes any excess up, a backward pass pushes it down; both are feasible, and so
 * is the floor of their mean, which splits the excess between the neighbours. A feasible
 * `wanted` is returned unchanged.
 */
std::vector<Count> feasible_cumulative(const std::vector<Count>& wanted,
                                       const std::vector<Count>& population) {
    const std::size_t n_bounds = wanted.size();  // m + 2
    const Count n_light = wanted.back();
    const CountBounds bounds = count_bounds(n_light, population);
    const std::vector<Count>&lower = bounds.lo, &upper = bounds.hi;

    std::vector<Count> forward(n_bounds), backward(n_bounds), result(n_bounds);
    forward[0] = 0;
    for (std::size_t j = 1; j < n_bounds; ++j)
        forward[j] = std::clamp(wanted[j], std::max(forward[j - 1], lower[j]),
                                std::min(forward[j - 1] + population[j - 1], upper[j]));
    backward[n_bounds - 1] = n_light;
    for (std::size_t j = n_bounds - 1; j-- > 0;)
        backward[j] = std::clamp(wanted[j], std::max(backward[j + 1] - population[j], lower[j]),
                                 std::min(backward[j + 1], upper[j]));
    for (std::size_t j = 0; j < n_bounds; ++j) result[j] = (forward[j] + backward[j]) / 2;
    return result;
}

/**
 * The feasible counts nearest `wanted`: B minimizing sum_j |B_j - W_j| (the lights placed
 * across a cut other than the target asks), then sum_j (B_j - W_j)^2 (an excess that can go
 * either way is split between the neighbours, not always sent one way), over L_j <= B_j <= U_j,
 * 0 <= B_{j+1} - B_j <= P_j (count_bounds). Where a short interval sits in
 * a run of full ones (a segregated bed: every particle above a cut light), the halves split
 * sends half the excess down the whole run, each cut off by it; this puts it where one cut
 * absorbs it (least squares alone would still send one particle down every cut: 18 cuts off by
 * one cost less than the 19th particle on the one cut). Dynamic programming over the m + 2
 * cuts: cost_j(b) = c(b - W_j) + min of cost_{j-1} over [b - P_{j-1}, b], the window minimum
 * by a monotone queue; O(sum of the bounds' ranges) <= O(m N_L) time and memory, run only when
 * `wanted` is infeasible. Exact integers; ties go to the count nearest W_j, then the lower.
 */
std::vector<Count> nearest_feasible_cumulative(const std::vector<Count>& wanted,
                                               const std::vector<Count>& population) {
    using Cost = std::pair<Count, Count>;  // (sum |d|, sum d^2), compared lexicographically
    const auto plus = [](const Cost& c, Count d) {
        return Cost{c.first + std::abs(d), c.second + d * d};
    };
    const std::size_t n_bounds = wanted.size();
    const Count n_light = wanted.back();
    const CountBounds bounds = count_bounds(n_light, population);
    const std::vector<Count>&lo = bounds.lo, &hi = bounds.hi;
    bool feasible = true;
    for (std::size_t j = 0; j < n_bounds; ++j) {
        feasible = feasible && wanted[j] >= lo[j] && wanted[j] <= hi[j] &&
                   (j == 0 ||
                    (wanted[j] >= wanted[j - 1] && wanted[j] - wanted[j - 1] <= population[j - 1]));
    }
    if (feasible) return wanted;
    // cost[j][b - lo[j]]; every b in [lo_j, hi_j] has a non-empty window (the bounds nest).
    std::vector<std::vector<Cost>> cost(n_bounds);
    cost[0].assign(1, Cost{0, 0});
    std::vector<Count> queue;  // the window's candidates b', their costs increasing
    for (std::size_t j = 1; j < n_bounds; ++j) {
        const auto& prev = cost[j - 1];
        const auto at = [&](Count b) { return prev[static_cast<std::size_t>(b - lo[j - 1])]; };
        auto& now = cost[j];
        now.resize(static_cast<std::size_t>(hi[j] - lo[j] + 1));
        queue.clear();
        std::size_t head = 0;
        Count next = lo[j - 1];  // the next b' to enter the window
        for (Count b = lo[j]; b <= hi[j]; ++b) {
            for (; next <= std::min(hi[j - 1], b); ++next) {
                while (queue.size() > head && at(queue.back()) >= at(next)) queue.pop_back();
                queue.push_back(next);
            }
            while (queue[head] < b - population[j - 1]) ++head;
            now[static_cast<std::size_t>(b - lo[j])] = plus(at(queue[head]), b - wanted[j]);
        }
    }
    std::vector<Count> result(n_bounds);
    result[n_bounds - 1] = n_light;
    for (std::size_t j = n_bounds - 1; j > 0; --j) {
        const auto at = [&](Count b) {
            return cost[j - 1][static_cast<std::size_t>(b - lo[j - 1])];
        };
        const Count b = result[j];
        const Count from = std::max(lo[j - 1], b - population[j - 1]), to = std::min(hi[j - 1], b);
        Count best = from;
        for (Count c = from + 1; c <= to; ++c)
            if (at(c) < at(best) ||
                (at(c) == at(best) && std::abs(c - wanted[j - 1]) < std::abs(best - wanted[j - 1])))
                best = c;
        result[j - 1] = best;
    }
    return result;
}

}  // namespace

std::uint32_t cuts_at_or_below(std::span<const double> cuts, double z) {
    const double* base = cuts.data();
    std::size_t len = cuts.size();
    while (len > 1) {
        const std::size_t half = len / 2;
        base = base[half] <= z ? base + half : base;
        len -= half;
    }
    return static_cast<std::uint32_t>(base - cuts.data()) + (*base <= z ? 1u : 0u);
}

std::vector<std::vector<std::size_t>> particles_by_interval(const LiftPlan& plan) {
    EFDEM_EXPECTS(plan.error.empty());
    std::vector<std::vector<std::size_t>> out(plan.population.size());
    for (std::size_t k = 0; k < out.size(); ++k)
        out[k].reserve(static_cast<std::size_t>(plan.population[k]));
    for (std::size_t j = 0; j < plan.interval.size(); ++j) out[plan.interval[j]].push_back(j);
    return out;
}

Eigen::VectorXd observed_icdf(std::span<const double> heights,
                              std::span<const std::uint8_t> colours, const ProbabilityGrid& grid) {
    EFDEM_EXPECTS(heights.size() == colours.size());
    std::vector<double> z;
    for (std::size_t j = 0; j < heights.size(); ++j)
        if (colours[j] == kLight) z.push_back(heights[j]);
    return quantiles(z, grid);
}

Count LiftPlan::shortfall() const {
    Count off = 0;
    for (std::size_t j = 0; j < below.size(); ++j)
        off = std::max(off, std::abs(below[j] - wanted[j]));
    return off;
}

std::string LiftPlan::shortage(std::string_view count_name, std::string_view remedy) const {
    if (below == wanted) return {};
    return fmt::format(
        "{} interval(s) held fewer particles than their {} count{}{} (a node's count off by up "
        "to {})",
        n_short_intervals, count_name, remedy.empty() ? "" : "; ", remedy, shortfall());
}

LiftPlan plan_lift(const Eigen::VectorXd& target_icdf, std::span<const double> heights,
                   std::span<const std::uint8_t> colours, const ProbabilityGrid& grid,
                   CountPlan counts) {
    EFDEM_EXPECTS(heights.size() == colours.size());
    EFDEM_EXPECTS(target_icdf.size() == grid.size());
    EFDEM_EXPECTS(std::all_of(colours.begin(), colours.end(),
                              [](std::uint8_t c) { return c == kLight || c == kHeavy; }));
    LiftPlan plan;
    plan.target = target_icdf;
    plan.n_observed = static_cast<Count>(std::count(colours.begin(), colours.end(), kLight));
    if (plan.n_observed == 0) {
        plan.error = "there are no light particles (the light ICDF is undefined)";
        return plan;
    }
    double z_min = std::numeric_limits<double>::infinity();
    double z_max = -std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < heights.size(); ++j) {
        if (!std::isfinite(heights[j])) {
            plan.error = fmt::format("the height of particle {} is not finite", j);
            return plan;
        }
        z_min = std::min(z_min, heights[j]);
        z_max = std::max(z_max, heights[j]);
    }
    if (!(z_min < z_max)) {
        plan.error =
            fmt::format("all particles are at the same height {:.6g}: no ICDF can change", z_min);
        return plan;
    }
    plan.repair = repair_monotone(plan.target, z_min, z_max);
    if (!plan.repair.feasible) {
        plan.error = plan.repair.message;
        return plan;
    }

    // Interval of each particle, populations and current observed counts: one sequential pass.
    const int m = grid.size();
    const auto n_intervals = static_cast<std::size_t>(m + 1);
    const std::span<const double> cuts(plan.target.data(), static_cast<std::size_t>(m));
    plan.interval.resize(heights.size());
    plan.population.assign(n_intervals, 0);
    plan.observed_now.assign(n_intervals, 0);
    for (std::size_t j = 0; j < heights.size(); ++j) {
        const std::uint32_t k = cuts_at_or_below(cuts, heights[j]);
        plan.interval[j] = k;
        ++plan.population[k];
        plan.observed_now[k] += colours[j] == kLight;
    }

    plan.wanted.assign(n_intervals + 1, 0);
    for (int i = 0; i < m; ++i)
        plan.wanted[static_cast<std::size_t>(i) + 1] =
            count_below_quantile(grid, i, plan.n_observed);
    plan.wanted.back() = plan.n_observed;
    plan.below = counts == CountPlan::nearest
                     ? nearest_feasible_cumulative(plan.wanted, plan.population)
                     : feasible_cumulative(plan.wanted, plan.population);
    for (std::size_t k = 0; k < n_intervals; ++k)
        if (plan.wanted[k + 1] - plan.wanted[k] > plan.population[k]) ++plan.n_short_intervals;
    return plan;
}

}  // namespace efdem::coarse
