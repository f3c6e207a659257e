#include "coarse/demixing/colour_lifting.hpp"

#include <algorithm>
#include <cmath>

#include "coarse/demixing/node_pins.hpp"
#include "coarse/demixing/quantiles.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

using Count = std::int64_t;

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
 * Relabels positions [first, last) of one interval's particles (`members`: sorted by height, or
 * in index order) so that exactly `wanted` of them are light, switching the fewest: the excess
 * colour's particles drawn at random (partial Fisher-Yates in the order of `members`, so
 * deterministic for a stream state), the `moving` ones first when flags are given. Returns the
 * labels switched.
 */
Count relabel_run(std::span<const std::size_t> members, std::size_t first, std::size_t last,
                  Count wanted, std::span<const std::uint8_t> colours,
                  std::span<const std::uint8_t> moving, std::vector<std::uint8_t>& out,
                  RandomStream& rng) {
    Count light = 0;
    for (std::size_t p = first; p < last; ++p) light += colours[members[p]] == kLight ? 1 : 0;
    const Count excess = light - wanted;
    EFDEM_ASSERT(wanted >= 0 && wanted <= static_cast<Count>(last - first));
    if (excess == 0) return 0;
    std::vector<std::size_t> first_drawn, rest;
    for (std::size_t p = first; p < last; ++p) {
        const std::size_t j = members[p];
        if ((colours[j] == kLight) == (excess > 0))
            (moving.empty() || moving[j] ? first_drawn : rest).push_back(j);
    }
    const Count from_first =
        std::min<Count>(std::abs(excess), static_cast<Count>(first_drawn.size()));
    switch_random(first_drawn, from_first, out, rng);
    switch_random(rest, std::abs(excess) - from_first, out, rng);
    return std::abs(excess);
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

/// Relabel::random: each interval switches |gain| particles of the colour it has too many of,
/// drawn at random among them in index order (the moving ones first). Returns the labels
/// switched.
std::size_t switch_at_random(const LiftPlan& plan, std::span<const std::uint8_t> colours,
                             std::span<const std::uint8_t> moving, std::vector<std::uint8_t>& out,
                             RandomStream& rng) {
    const std::vector<std::vector<std::size_t>> members = particles_by_interval(plan);
    Count changed = 0;
    for (std::size_t k = 0; k < members.size(); ++k)
        changed += relabel_run(members[k], 0, members[k].size(), plan.below[k + 1] - plan.below[k],
                               colours, moving, out, rng);
    return static_cast<std::size_t>(changed);
}

/// Relabel::at_nodes: each node's defining ranks pinned on the particles that meet it best
/// (node_pins.hpp); between and beyond an interval's pins, the fewest switches at random.
/// Returns the labels switched.
std::size_t switch_at_nodes(const LiftPlan& plan, std::span<const double> heights,
                            std::span<const std::uint8_t> colours, const ProbabilityGrid& grid,
                            std::span<const std::uint8_t> moving, std::vector<std::uint8_t>& out,
                            RandomStream& rng) {
    const IntervalOrder order = order_intervals(plan, heights);
    const std::vector<RankPin> pins = pin_node_ranks(plan, order, heights, colours, grid, moving);
    auto pin = pins.begin();
    Count changed = 0;
    for (std::size_t k = 0; k < order.size(); ++k) {
        std::size_t start = 0;
        Count placed = 0;  // observed particles of interval k below position `start`
        for (; pin != pins.end() && pin->interval == k; ++pin) {
            changed += relabel_run(order[k], start, pin->position, pin->offset - placed, colours,
                                   moving, out, rng);
            const std::size_t j = order[k][pin->position];
            changed += colours[j] == kLight ? 0 : 1;
            out[j] = kLight;
            placed = pin->offset + 1;
            start = pin->position + 1;
        }
        changed +=
            relabel_run(order[k], start, order[k].size(),
                        plan.below[k + 1] - plan.below[k] - placed, colours, moving, out, rng);
    }
    return static_cast<std::size_t>(changed);
}

}  // namespace

LiftResult lift_colours(const Eigen::VectorXd& target_icdf, std::span<const double> heights,
                        std::span<const std::uint8_t> colours, const ProbabilityGrid& grid,
                        RandomStream& rng, std::span<const std::uint8_t> moving, Relabel relabel) {
    EFDEM_EXPECTS(moving.empty() || moving.size() == colours.size());  // the rest: plan_lift
    LiftResult result;
    result.colours.assign(colours.begin(), colours.end());
    result.target = target_icdf;
    auto reject = [&](std::string why) {
        result.status = LiftStatus::rejected;
        result.message = "lifting rejected, no label changed: " + std::move(why);
        if (std::count(colours.begin(), colours.end(), kLight) > 0 &&
            std::all_of(heights.begin(), heights.end(), [](double z) { return std::isfinite(z); }))
            result.achieved_icdf = observed_icdf(heights, colours, grid);
        return result;
    };

    LiftPlan plan =
        plan_lift(target_icdf, heights, colours, grid,
                  relabel == Relabel::at_nodes ? CountPlan::nearest : CountPlan::halves);
    if (!plan.error.empty()) return reject(plan.error);
    result.target = plan.target;
    result.repair = plan.repair;
    result.n_short_intervals = plan.n_short_intervals;
    result.n_changed =
        relabel == Relabel::at_nodes
            ? switch_at_nodes(plan, heights, colours, grid, moving, result.colours, rng)
            : switch_at_random(plan, colours, moving, result.colours, rng);

    result.achieved_icdf =
        achieved_light_icdf(heights, result.colours, plan.interval, plan.below, grid);
    result.max_deviation = (result.achieved_icdf - result.target).cwiseAbs().maxCoeff();
    const bool short_counts = plan.below != plan.wanted;
    result.status = result.repair.changed() || short_counts ? LiftStatus::adjusted : LiftStatus::ok;
    result.message = result.repair.message;
    if (short_counts)
        result.message += (result.message.empty() ? "" : "; ") +
                          plan.shortage("light", "light particles moved to neighbouring intervals");
    EFDEM_ENSURES(std::count(result.colours.begin(), result.colours.end(), kLight) ==
                  plan.n_observed);
    return result;
}

}  // namespace efdem::coarse
