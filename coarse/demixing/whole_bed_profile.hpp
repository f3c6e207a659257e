#pragma once
/// \file
/// The whole bed's height distribution as a monotone map between heights and ranks, for the
/// rank coordinates (cpi.observable = ranks, rank_observable.hpp).
///
/// A profile is the ICDF of ALL particle heights of one realization at kWholeBedNodes ranks:
/// u_0 = 0 (the lowest particle centre), u_1..u_99 = 0.01..0.99 (the p-grid of 99 nodes, with
/// quantiles.hpp's convention) and u_100 = 1 (the highest particle centre). Between the nodes the
/// map is linear, so Q(u) (ranks -> heights, heights_at) and F(z) (heights -> ranks, ranks_in)
/// are exact inverses of each other: a height mapped to its rank and back is the same height
/// (to rounding), which is what makes lifting through a profile consistent with restricting
/// through it. Every particle height lies in [Q(0), Q(1)], so every height has a rank.
/// Heights in d_p, ranks dimensionless. Generic: no DEM, no MPI.

#include <vector>

#include <Eigen/Core>

#include "coarse/demixing/probability_grid.hpp"

namespace efdem::coarse {

/// Entries of a profile: the two ends and the 99 interior nodes. With 1,000 particles one
/// interval of the map holds 10 of them; the rank of a height is exact at the nodes and linear
/// in between.
inline constexpr Eigen::Index kWholeBedNodes = 101;

/// The interior nodes' grid (p = 0.01, ..., 0.99).
ProbabilityGrid whole_bed_interior_grid();

/// The profile of a bed whose particle centres are at `heights` (any order; at least one).
Eigen::VectorXd profile_of_heights(std::vector<double> heights);

/// The ranks u_k of the profile's entries: 0, 0.01, ..., 0.99, 1.
Eigen::VectorXd whole_bed_ranks();

/// F(z_i) for each height: the rank of z_i in `profile`, linear between the nodes; a height on a
/// flat stretch (equal heights at neighbouring nodes) gets the middle of its ranks; heights
/// outside [profile(0), profile(last)] get 0 or 1. NaN stays NaN.
/// \pre profile.size() == kWholeBedNodes, non-decreasing, finite.
Eigen::VectorXd ranks_in(const Eigen::VectorXd& heights, const Eigen::VectorXd& profile);

/// Q(u_i) for each rank: the height at rank u_i in `profile`, linear between the nodes; ranks
/// are clamped into [0, 1]. NaN stays NaN. \pre as ranks_in().
Eigen::VectorXd heights_at(const Eigen::VectorXd& ranks, const Eigen::VectorXd& profile);

}  // namespace efdem::coarse
