#pragma once
/// \file
/// The empirical quantile function (ICDF) of a set of particle heights (physics.md §8).
///
/// Convention: sort the n heights z_(1) <= ... <= z_(n). Q(p) interpolates linearly between the
/// points ((k - 1/2)/n, z_(k)), k = 1..n, and is constant beyond the end points:
/// Q(p) = z_(1) for p <= 1/(2n) and Q(p) = z_(n) for p >= 1 - 1/(2n). For n = 1, Q = z_(1).
/// Heights are in particle diameters d_p; p is dimensionless.

#include <cstdint>
#include <functional>
#include <span>

#include <Eigen/Core>

#include "coarse/demixing/probability_grid.hpp"

namespace efdem::coarse {

/// Where node i falls in a sorted sample of n points: Q(p_i) = (1 - fraction) z[lower] +
/// fraction z[lower + 1] (0-based), with fraction = 0 when the node sits on a point or beyond
/// the end points. \pre n >= 1.
struct NodeRank {
    std::int64_t lower = 0;
    double fraction = 0.0;
};
NodeRank node_rank(const ProbabilityGrid& grid, int i, std::int64_t n);

/// Q(p) of heights already sorted ascending. \pre sorted non-empty, ascending, finite; 0 <= p <= 1.
double quantile_sorted(std::span<const double> sorted, double p);

/**
 * \brief (Q(p_0), ..., Q(p_{m-1})) of heights already sorted ascending. O(m).
 *
 * Node positions are computed exactly from the grid's rationals: the 0-based fractional rank of
 * p_i is r_i = p_i n - 1/2 = (2 (i+1) n - (m+1)) / (2 (m+1)).
 * \pre sorted non-empty, ascending, finite.
 */
Eigen::VectorXd quantiles_sorted(std::span<const double> sorted, const ProbabilityGrid& grid);

/**
 * \brief (Q(p_0), ..., Q(p_{m-1})) of unsorted heights.
 *
 * Copies the heights and selects only the order statistics the nodes need (recursive
 * nth_element): O(n log m), not O(n log n). The result equals quantiles_sorted() of the sorted
 * heights exactly. \pre heights non-empty and finite.
 */
Eigen::VectorXd quantiles(std::span<const double> heights, const ProbabilityGrid& grid);

/**
 * \brief (Q(p_0), ..., Q(p_{m-1})) of n points given only access to their order statistics:
 *        `order_statistic(k)` returns the k-th smallest (0-based) and is called only for the
 *        at most 2 m ranks the nodes need.
 *
 * For callers that can find an order statistic faster than by selecting over all n points
 * (colour lifting knows which interval of heights holds each rank). Same values, bit for bit,
 * as quantiles_sorted(). \pre n >= 1.
 */
Eigen::VectorXd quantiles_from_order_statistics(
    std::int64_t n, const ProbabilityGrid& grid,
    const std::function<double(std::int64_t)>& order_statistic);

/**
 * \brief Number of the n sample points that lie strictly below Q(p_i), for distinct points:
 *        C_i = clamp(ceil(r_i), 0, n - 1) with r_i = p_i n - 1/2.
 *
 * This is the inverse statement of the quantile convention that lifting needs: a sample of n
 * distinct points has Q(p_i) = z* exactly when C_i of them lie below z* and the others at or
 * above it, with z* between the C_i-th and the (C_i + 1)-th point. Computed in integers.
 * \pre n >= 1, 0 <= i < grid.size().
 */
std::int64_t count_below_quantile(const ProbabilityGrid& grid, int i, std::int64_t n);

}  // namespace efdem::coarse
