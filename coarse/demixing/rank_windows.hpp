#pragma once
/// \file
/// Lifting rank by rank (docs/lifting_by_positions.md "Placing each sphere"): the height each
/// order statistic of n observed particles should have for their ICDF to equal a target, the
/// window around it in which a particle may stay, and which particles already lie in theirs.
/// A lift that moves only the others, each to its rank's height, leaves every node of the ICDF
/// within the windows' half-width of the target, however few particles there are.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "coarse/demixing/probability_grid.hpp"

namespace efdem::coarse {

struct RankWindows {
    /// Height for each rank r = 0..n-1 (0-based, ascending) [d_p], non-decreasing. The ranks
    /// that define a node (quantiles.hpp: node_rank) are placed about the node's target with its
    /// local slope, so that the quantile convention returns the target exactly; the others on
    /// the target interpolated linearly in rank, extrapolated with the end slopes, and every
    /// height clipped into [z_low, z_high]. Exact when no two nodes share a rank (n >= 2 (m+1));
    /// with fewer particles a shared rank takes the upper node's height and the lower node is
    /// off by up to the target's change over one rank.
    std::vector<double> desired;
    /// Window of each rank: a defining rank's desired height +- half_width, any other rank's
    /// from the window below of its nearest defining rank below to the window above of its
    /// nearest defining rank above (unbounded beyond the first and last defining ranks).
    /// Both ends non-decreasing in r.
    std::vector<double> low, high;
    /// 1 for a rank that defines a node.
    std::vector<std::uint8_t> defining;
};

/**
 * \brief The rank heights and windows for n observed particles and the (repaired,
 *        non-decreasing) `target` ICDF.
 *
 * Guarantee: if the particle of every sorted rank r lies in [low_r, high_r], every node of
 * their ICDF lies within half_width of the target (the k-th smallest height lies in rank k's
 * window, since at least k + 1 windows end at or below high_k and n - k begin at or above
 * low_k). Tested in tests/coarse/test_rank_windows.cpp.
 * \pre target.size() == grid.size(), target non-decreasing; n >= 1; half_width >= 0;
 *      z_low <= z_high.
 */
RankWindows rank_windows(const Eigen::VectorXd& target, const ProbabilityGrid& grid, std::int64_t n,
                         double half_width, double z_low, double z_high);

/**
 * \brief For heights sorted ascending, the rank each keeps (-1: it must move): the largest
 *        order-preserving assignment of particles to ranks whose windows hold them.
 *
 * Greedy, O(n): each particle in turn takes the lowest free rank above the last one taken
 * whose window holds it; a particle below the window of that rank fits no later one (the
 * windows are monotone) and moves. Taking the lowest feasible rank never costs a later particle
 * a match (the usual exchange argument), so no assignment keeps more particles.
 * \pre sorted_heights ascending, of size windows.desired.size().
 */
std::vector<std::int64_t> ranks_kept(std::span<const double> sorted_heights,
                                     const RankWindows& windows);

}  // namespace efdem::coarse
