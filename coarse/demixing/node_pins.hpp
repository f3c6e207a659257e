#pragma once
/// \file
/// Which particles should hold the ranks that define the ICDF's nodes after a colour lift
/// (docs/lifting_by_positions.md is the moving counterpart). The count plan (lift_plan.hpp) puts
/// the right number of observed particles below every cut, but a node Q(p_i) is the weighted
/// mean of two order statistics (quantiles.hpp: node_rank), and which particles of an interval
/// end up as its lowest and highest observed ones decides how far the node lands from its target.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "coarse/demixing/lift_plan.hpp"
#include "coarse/demixing/probability_grid.hpp"

namespace efdem::coarse {

/// The particles of each of the plan's m + 1 intervals, ascending in height (ties by index).
using IntervalOrder = std::vector<std::vector<std::size_t>>;

/// particles_by_interval(plan), each interval sorted by height: O(N log(N / m)).
IntervalOrder order_intervals(const LiftPlan& plan, std::span<const double> heights);

/// A rank of the observed species fixed on one particle: the particle is (made) observed and
/// is the `offset`-th observed one of its interval from below.
struct RankPin {
    std::int64_t rank = 0;     ///< 0-based rank among all N_L observed particles
    std::size_t interval = 0;  ///< its interval k (below[k] <= rank < below[k+1])
    std::int64_t offset = 0;   ///< rank - below[k]
    std::size_t position = 0;  ///< index into order[k]
};

/**
 * \brief For every node, the particles that hold its defining ranks (node_rank: `lower`, and
 *        `lower + 1` when its fraction is not 0), chosen so that the node meets its target.
 *
 * Nodes are taken bottom-up. A rank pinned by an earlier node stays. For a free rank the
 * candidates are the particles of its interval around the target height (the `reach` nearest on
 * each side) and the observed particles nearest it from below and above, all within the room
 * the interval's count leaves: pin positions p of offsets o in one interval of P particles and
 * n observed satisfy p >= o, p' - p >= o' - o between pins, and p <= P - n + o, so the other
 * observed particles always fit between and beyond the pins. Among the candidate pairs the one
 * whose node (1 - f) z_lower + f z_upper is nearest the target wins; among those within 1e-9
 * d_p of it, the one that switches fewest labels (an already observed particle costs none). A
 * target equal to the current ICDF thus keeps the current particles (their node is exact), and
 * no node can end farther from its target than the best candidate pair allows.
 *
 * `prefer` (optional, one flag per particle): a particle without the flag is a candidate only
 * if it is already observed (cpi.relabel = moving: labels switch where the bed moves); if that
 * leaves no candidate, every particle in the room is one.
 *
 * Returns the pins ascending in rank (and so in interval and position).
 * \pre plan without error; order = order_intervals(plan, heights); colours of heights' size;
 *      prefer empty or of heights' size; reach >= 1.
 */
std::vector<RankPin> pin_node_ranks(const LiftPlan& plan, const IntervalOrder& order,
                                    std::span<const double> heights,
                                    std::span<const std::uint8_t> colours,
                                    const ProbabilityGrid& grid,
                                    std::span<const std::uint8_t> prefer = {}, int reach = 4);

}  // namespace efdem::coarse
