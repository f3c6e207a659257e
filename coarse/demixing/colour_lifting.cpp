#include "coarse/demixing/colour_lifting.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "coarse/demixing/quantiles.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

using Count = std::int64_t;

/// Q_L of the particles labelled light, on the grid.
Eigen::VectorXd light_icdf(std::span<const double> heights, std::span<const std::uint8_t> colours,
                           const ProbabilityGrid& grid) {
    std::vector<double> light;
    for (std::size_t j = 0; j < heights.size(); ++j)
        if (colours[j] == kLight) light.push_back(heights[j]);
    return quantiles(light, grid);
}

/**
 * Light counts below each cut: `wanted` (B_0 = 0, ..., B_{m+1} = N_L) made feasible for
 * interval populations `population` (0 <= B_{k+1} - B_k <= P_k). Feasible bounds at boundary j:
 * L_j = max(0, N_L - (N - S_j)) <= B_j <= U_j = min(N_L, S_j), S_j = particles below it. A
 * forward pass pushes any excess up, a backward pass pushes it down; both are feasible, and so
 * is the floor of their mean, which splits the excess between the neighbours. A feasible
 * `wanted` is returned unchanged.
 */
std::vector<Count> feasible_cumulative(const std::vector<Count>& wanted,
                                       const std::vector<Count>& population) {
    const std::size_t n_bounds = wanted.size();  // m + 2
    const Count n_light = wanted.back();
    std::vector<Count> below(n_bounds, 0);
    for (std::size_t j = 1; j < n_bounds; ++j) below[j] = below[j - 1] + population[j - 1];
    const Count total = below.back();
    auto lower = [&](std::size_t j) { return std::max<Count>(0, n_light - (total - below[j])); };
    auto upper = [&](std::size_t j) { return std::min<Count>(n_light, below[j]); };

    std::vector<Count> forward(n_bounds), backward(n_bounds), result(n_bounds);
    forward[0] = 0;
    for (std::size_t j = 1; j < n_bounds; ++j)
        forward[j] = std::clamp(wanted[j], std::max(forward[j - 1], lower(j)),
                                std::min(forward[j - 1] + population[j - 1], upper(j)));
    backward[n_bounds - 1] = n_light;
    for (std::size_t j = n_bounds - 1; j-- > 0;)
        backward[j] = std::clamp(wanted[j], std::max(backward[j + 1] - population[j], lower(j)),
                                 std::min(backward[j + 1], upper(j)));
    for (std::size_t j = 0; j < n_bounds; ++j) result[j] = (forward[j] + backward[j]) / 2;
    return result;
}

/// Number of cuts at or below z (the cuts sorted, m >= 1): a binary search whose halving step
/// compiles to a conditional move (Khuong & Morin 2017), ~10 ns for m = 19 against ~30 ns for
/// std::upper_bound, whose branches on random heights the CPU cannot predict.
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

/// Switches `count` of the `candidates` (all of one colour, in index order) to the other
/// colour, chosen uniformly by a partial Fisher-Yates shuffle: deterministic for a stream state.
void switch_random(std::vector<std::size_t>& candidates, Count count,
                   std::vector<std::uint8_t>& colours, RandomStream& rng) {
    EFDEM_ASSERT(static_cast<Count>(candidates.size()) >= count);
    for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i) {
        std::swap(candidates[i], candidates[i + rng.below(candidates.size() - i)]);
        colours[candidates[i]] ^= 1u;  // kHeavy <-> kLight
    }
}

/**
 * Q_L of the new labels from interval buckets: the light particles of interval k are ranks
 * below[k] .. below[k+1]-1 of all light particles, so each order statistic the nodes need is
 * selected within one bucket. The nodes need the ranks next to the cuts, i.e. a bucket's
 * lowest or highest, so each bucket is scanned a few times: O(N) in all, against
 * O(N_L log m) for a selection over all light particles. Buckets are filled in one sequential
 * pass over the particles.
 */
Eigen::VectorXd achieved_light_icdf(std::span<const double> heights,
                                    std::span<const std::uint8_t> colours,
                                    std::span<const std::uint32_t> interval,
                                    std::span<const Count> below, const ProbabilityGrid& grid) {
    std::vector<double> light_z(static_cast<std::size_t>(below.back()));
    std::vector<Count> fill(below.begin(), below.end() - 1);
    for (std::size_t j = 0; j < heights.size(); ++j)
        if (colours[j] == kLight)
            light_z[static_cast<std::size_t>(fill[interval[j]]++)] = heights[j];
    return quantiles_from_order_statistics(below.back(), grid, [&](Count rank) {
        const auto k = static_cast<std::size_t>(std::upper_bound(below.begin(), below.end(), rank) -
                                                below.begin() - 1);
        const auto first = light_z.begin() + below[k], last = light_z.begin() + below[k + 1];
        // The ranks next to a cut are a bucket's lowest or highest: one pass, no swaps.
        if (rank == below[k]) return *std::min_element(first, last);
        if (rank == below[k + 1] - 1) return *std::max_element(first, last);
        std::nth_element(first, light_z.begin() + rank, last);
        return light_z[static_cast<std::size_t>(rank)];
    });
}

}  // namespace

LiftResult lift_colours(const Eigen::VectorXd& target_icdf, std::span<const double> heights,
                        std::span<const std::uint8_t> colours, const ProbabilityGrid& grid,
                        RandomStream& rng, std::span<const std::uint8_t> moving) {
    EFDEM_EXPECTS(heights.size() == colours.size());
    EFDEM_EXPECTS(moving.empty() || moving.size() == colours.size());
    EFDEM_EXPECTS(target_icdf.size() == grid.size());
    EFDEM_EXPECTS(std::all_of(colours.begin(), colours.end(),
                              [](std::uint8_t c) { return c == kLight || c == kHeavy; }));
    LiftResult result;
    result.colours.assign(colours.begin(), colours.end());
    result.target = target_icdf;
    auto reject = [&](std::string why) {
        result.status = LiftStatus::rejected;
        result.message = "lifting rejected, no label changed: " + std::move(why);
        if (std::count(colours.begin(), colours.end(), kLight) > 0 &&
            std::all_of(heights.begin(), heights.end(), [](double z) { return std::isfinite(z); }))
            result.achieved_icdf = light_icdf(heights, colours, grid);
        return result;
    };

    const auto n_light = static_cast<Count>(std::count(colours.begin(), colours.end(), kLight));
    if (n_light == 0) return reject("there are no light particles (the light ICDF is undefined)");
    double z_min = std::numeric_limits<double>::infinity();
    double z_max = -std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < heights.size(); ++j) {
        if (!std::isfinite(heights[j]))
            return reject(fmt::format("the height of particle {} is not finite", j));
        z_min = std::min(z_min, heights[j]);
        z_max = std::max(z_max, heights[j]);
    }
    if (!(z_min < z_max))
        return reject(
            fmt::format("all particles are at the same height {:.6g}: no ICDF can "
                        "change",
                        z_min));
    result.repair = repair_monotone(result.target, z_min, z_max);
    if (!result.repair.feasible) return reject(result.repair.message);

    // Interval of each particle (number of cuts at or below its height), populations and
    // current light counts: one sequential pass.
    const int m = grid.size();
    const auto n_intervals = static_cast<std::size_t>(m + 1);
    const std::span<const double> cuts(result.target.data(), static_cast<std::size_t>(m));
    std::vector<std::uint32_t> interval(heights.size());
    std::vector<Count> population(n_intervals, 0), light_now(n_intervals, 0);
    for (std::size_t j = 0; j < heights.size(); ++j) {
        const std::uint32_t k = cuts_at_or_below(cuts, heights[j]);
        interval[j] = k;
        ++population[k];
        light_now[k] += colours[j] == kLight;
    }

    // Light counts below each cut: wanted (rounded cumulative targets), then made feasible.
    std::vector<Count> wanted(n_intervals + 1, 0);
    for (int i = 0; i < m; ++i)
        wanted[static_cast<std::size_t>(i) + 1] = count_below_quantile(grid, i, n_light);
    wanted.back() = n_light;
    const std::vector<Count> below = feasible_cumulative(wanted, population);

    // Interval k switches |excess_k| particles of the colour it has too many of; the
    // candidates are collected in one sequential pass (index order, so the draw is
    // deterministic), then drawn without replacement.
    std::vector<Count> excess(n_intervals);
    std::vector<std::vector<std::size_t>> candidates(n_intervals);
    for (std::size_t k = 0; k < n_intervals; ++k) {
        excess[k] = light_now[k] - (below[k + 1] - below[k]);
        if (wanted[k + 1] - wanted[k] > population[k]) ++result.n_short_intervals;
        if (excess[k] != 0)
            candidates[k].reserve(static_cast<std::size_t>(
                excess[k] > 0 ? light_now[k] : population[k] - light_now[k]));
    }
    // With `moving`, an interval's moving candidates are drawn first, the still ones only for
    // what is left: the same counts, labels changed where the bed moves.
    std::vector<std::vector<std::size_t>> still(moving.empty() ? 0 : n_intervals);
    for (std::size_t j = 0; j < heights.size(); ++j) {
        const Count e = excess[interval[j]];
        if (e == 0 || (colours[j] == kLight) != (e > 0)) continue;
        (moving.empty() || moving[j] ? candidates : still)[interval[j]].push_back(j);
    }
    for (std::size_t k = 0; k < n_intervals; ++k) {
        if (excess[k] == 0) continue;
        const Count first =
            std::min<Count>(std::abs(excess[k]), static_cast<Count>(candidates[k].size()));
        switch_random(candidates[k], first, result.colours, rng);
        if (first < std::abs(excess[k]))
            switch_random(still[k], std::abs(excess[k]) - first, result.colours, rng);
        result.n_changed += static_cast<std::size_t>(std::abs(excess[k]));
    }

    result.achieved_icdf = achieved_light_icdf(heights, result.colours, interval, below, grid);
    result.max_deviation = (result.achieved_icdf - result.target).cwiseAbs().maxCoeff();
    const bool short_counts = below != wanted;
    result.status = result.repair.changed() || short_counts ? LiftStatus::adjusted : LiftStatus::ok;
    result.message = result.repair.message;
    if (short_counts) {
        Count moved = 0;
        for (std::size_t j = 0; j < below.size(); ++j)
            moved = std::max(moved, std::abs(below[j] - wanted[j]));
        result.message += fmt::format(
            "{}{} interval(s) held fewer particles than their light count; light particles "
            "moved to neighbouring intervals (a node's count off by up to {})",
            result.message.empty() ? "" : "; ", result.n_short_intervals, moved);
    }
    EFDEM_ENSURES(std::count(result.colours.begin(), result.colours.end(), kLight) == n_light);
    return result;
}

}  // namespace efdem::coarse
