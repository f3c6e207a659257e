#include "coarse/demixing/colour_lifting.hpp"

#include <algorithm>
#include <array>
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

/// The candidates' order of preference (SwitchOrder) when `to_light` particles turn light (else
/// heavy): 0 first. Each class is drawn from uniformly.
std::uint8_t preference(const SwitchOrder& order, std::size_t j, bool to_light) {
    switch (order.by) {
        case SwitchOrder::By::any:
            return 0;
        case SwitchOrder::By::moving:
            return order.values[j] ? 0 : 1;
        case SwitchOrder::By::light_neighbours:
            return to_light ? static_cast<std::uint8_t>(255 - order.values[j]) : order.values[j];
        case SwitchOrder::By::like_lights:
            return 0;                         // drawn by weight (switch_like_lights) or uniformly
        case SwitchOrder::By::keep_clusters:  // turning light: by weight (switch_like_lights)
            return to_light ? 0 : order.values[j];
    }
    return 0;
}

/**
 * SwitchOrder::By::like_lights, heavies turning light: `count` of the `candidates` (heavies)
 * drawn without replacement with weights w(c) = P_L(c) / P_H(c), c a particle's light-neighbour
 * count, P_L the distribution of c over `lights` (with half a light spread over the counts, so
 * a count no light has keeps a small weight) and P_H over the candidates: the drawn heavies' counts
 * are distributed as the lights' (exactly so for a draw with replacement). Efraimidis-Spirakis:
 * each candidate's key log(u) / w, the `count` largest switch; deterministic for a stream state.
 */
void switch_like_lights(std::span<const std::size_t> candidates,
                        std::span<const std::size_t> lights, Count count,
                        std::span<const std::uint8_t> values, std::vector<std::uint8_t>& colours,
                        RandomStream& rng) {
    std::array<double, 256> p_light{}, p_heavy{};
    int top = 0;
    for (const std::size_t j : candidates) top = std::max<int>(top, values[j]);
    for (const std::size_t j : lights) top = std::max<int>(top, values[j]);
    // Half a light spread over the counts seen: a count no light has keeps a small weight.
    for (int c = 0; c <= top; ++c) p_light[static_cast<std::size_t>(c)] = 0.5 / (top + 1);
    for (const std::size_t j : lights) p_light[values[j]] += 1.0;
    for (const std::size_t j : candidates) p_heavy[values[j]] += 1.0;
    std::vector<std::pair<double, std::size_t>> keyed;
    keyed.reserve(candidates.size());
    for (const std::size_t j : candidates) {
        const double w = p_light[values[j]] / p_heavy[values[j]];  // up to a common factor
        keyed.emplace_back(std::log(std::max(rng.uniform(), 1e-300)) / w, j);
    }
    std::partial_sort(keyed.begin(), keyed.begin() + count, keyed.end(),
                      [](const auto& a, const auto& b) { return a.first > b.first; });
    for (Count k = 0; k < count; ++k) colours[keyed[static_cast<std::size_t>(k)].second] ^= 1u;
}

/**
 * Relabels positions [first, last) of one interval's particles (`members`: sorted by height, or
 * in index order) so that exactly `wanted` of them are light, switching the fewest: the excess
 * colour's particles drawn at random (partial Fisher-Yates in the order of `members`, so
 * deterministic for a stream state), class by class in `order`'s preference. Returns the labels
 * switched.
 */
Count relabel_run(std::span<const std::size_t> members, std::size_t first, std::size_t last,
                  Count wanted, std::span<const std::uint8_t> colours, const SwitchOrder& order,
                  std::vector<std::uint8_t>& out, RandomStream& rng) {
    Count light = 0;
    for (std::size_t p = first; p < last; ++p) light += colours[members[p]] == kLight ? 1 : 0;
    const Count excess = light - wanted;
    EFDEM_ASSERT(wanted >= 0 && wanted <= static_cast<Count>(last - first));
    if (excess == 0) return 0;
    if (SwitchOrder::draws_like_lights(order.by) && excess < 0) {
        std::vector<std::size_t> heavies, lights;
        for (std::size_t p = first; p < last; ++p)
            (colours[members[p]] == kLight ? lights : heavies).push_back(members[p]);
        switch_like_lights(heavies, lights, -excess, order.values, out, rng);
        return -excess;
    }
    // The candidates by class (a stable sort on the class byte), index order within each.
    std::vector<std::pair<std::uint8_t, std::size_t>> candidates;
    for (std::size_t p = first; p < last; ++p) {
        const std::size_t j = members[p];
        if ((colours[j] == kLight) == (excess > 0))
            candidates.emplace_back(preference(order, j, excess < 0), j);
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    Count left = std::abs(excess);
    for (std::size_t a = 0; a < candidates.size() && left > 0;) {
        std::size_t b = a;
        std::vector<std::size_t> cls;
        for (; b < candidates.size() && candidates[b].first == candidates[a].first; ++b)
            cls.push_back(candidates[b].second);
        const Count here = std::min<Count>(left, static_cast<Count>(cls.size()));
        switch_random(cls, here, out, rng);
        left -= here;
        a = b;
    }
    EFDEM_ASSERT(left == 0);
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
/// drawn at random among them in index order (in `order`'s preference). Returns the labels
/// switched.
std::size_t switch_at_random(const LiftPlan& plan, std::span<const std::uint8_t> colours,
                             const SwitchOrder& order, std::vector<std::uint8_t>& out,
                             RandomStream& rng) {
    const std::vector<std::vector<std::size_t>> members = particles_by_interval(plan);
    Count changed = 0;
    for (std::size_t k = 0; k < members.size(); ++k)
        changed += relabel_run(members[k], 0, members[k].size(), plan.below[k + 1] - plan.below[k],
                               colours, order, out, rng);
    return static_cast<std::size_t>(changed);
}

/// Relabel::at_nodes: each node's defining ranks pinned on the particles that meet it best
/// (node_pins.hpp); between and beyond an interval's pins, the fewest switches at random.
/// Returns the labels switched.
std::size_t switch_at_nodes(const LiftPlan& plan, std::span<const double> heights,
                            std::span<const std::uint8_t> colours, const ProbabilityGrid& grid,
                            const SwitchOrder& switch_order, std::vector<std::uint8_t>& out,
                            RandomStream& rng) {
    const IntervalOrder order = order_intervals(plan, heights);
    // The pins prefer moving particles (cpi.relabel = moving); other orders leave them alike.
    const std::span<const std::uint8_t> moving = switch_order.by == SwitchOrder::By::moving
                                                     ? switch_order.values
                                                     : std::span<const std::uint8_t>{};
    const std::vector<RankPin> pins = pin_node_ranks(plan, order, heights, colours, grid, moving);
    auto pin = pins.begin();
    Count changed = 0;
    for (std::size_t k = 0; k < order.size(); ++k) {
        std::size_t start = 0;
        Count placed = 0;  // observed particles of interval k below position `start`
        for (; pin != pins.end() && pin->interval == k; ++pin) {
            changed += relabel_run(order[k], start, pin->position, pin->offset - placed, colours,
                                   switch_order, out, rng);
            const std::size_t j = order[k][pin->position];
            changed += colours[j] == kLight ? 0 : 1;
            out[j] = kLight;
            placed = pin->offset + 1;
            start = pin->position + 1;
        }
        changed += relabel_run(order[k], start, order[k].size(),
                               plan.below[k + 1] - plan.below[k] - placed, colours, switch_order,
                               out, rng);
    }
    return static_cast<std::size_t>(changed);
}

}  // namespace

LiftResult lift_colours(const Eigen::VectorXd& target_icdf, std::span<const double> heights,
                        std::span<const std::uint8_t> colours, const ProbabilityGrid& grid,
                        RandomStream& rng, SwitchOrder order, Relabel relabel) {
    EFDEM_EXPECTS(order.by == SwitchOrder::By::any ||
                  order.values.size() == colours.size());  // the rest: plan_lift
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
            ? switch_at_nodes(plan, heights, colours, grid, order, result.colours, rng)
            : switch_at_random(plan, colours, order, result.colours, rng);

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
