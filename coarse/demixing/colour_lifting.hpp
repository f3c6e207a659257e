#pragma once
/// \file
/// Lifting by minimal-change recolouring (physics.md §9): the particle positions are reused and
/// only species labels switch, until the light-species ICDF matches a target.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "coarse/demixing/lift_plan.hpp"
#include "coarse/demixing/monotone_repair.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "core/rng.hpp"

namespace efdem::coarse {

enum class LiftStatus {
    ok,        ///< target met as given: no repair, every interval could take its light count
    adjusted,  ///< applied, but the target was repaired/clipped, or an interval had fewer
               ///< particles than its light count and the excess went to its neighbours
    rejected,  ///< nothing changed: non-finite target or heights, no light particle, or all
               ///< heights equal
};

struct LiftResult {
    LiftStatus status = LiftStatus::rejected;
    /// The new labels (a copy of the input when rejected).
    std::vector<std::uint8_t> colours;
    /// Labels switched; always even (as many light -> heavy as heavy -> light).
    std::size_t n_changed = 0;
    /// The target actually aimed at: after monotone repair and clipping into the height range.
    Eigen::VectorXd target;
    /// Q_L of the new labels on the grid [d_p] (of the old ones when rejected).
    Eigen::VectorXd achieved_icdf;
    /// max_i |achieved_icdf_i - target_i| [d_p].
    double max_deviation = 0.0;
    RepairReport repair;
    /// Intervals that held fewer particles than their light count.
    int n_short_intervals = 0;
    /// Empty when status is ok; otherwise what was adjusted or why nothing was done.
    std::string message;

    bool applied() const { return status != LiftStatus::rejected; }
};

/**
 * \brief Recolours particles so that the light ICDF becomes `target_icdf` (physics.md §9 steps
 *        1-3 and 5), changing as few labels as the interval counts allow.
 *
 * 1. The target is made non-decreasing (isotonic regression) and clipped into
 *    [min height, max height] (repair_monotone); the result is `target`, z*_0 <= ... <= z*_{m-1}.
 * 2. The heights are cut at the z*_i into m + 1 intervals I_0 = (-inf, z*_0),
 *    I_k = [z*_{k-1}, z*_k), I_m = [z*_{m-1}, inf). The light count below z*_i is set to
 *    C_i = count_below_quantile(grid, i, N_L), i.e. round(p_i N_L) with halves rounded down
 *    (capped at N_L - 1), so n_k = C_k - C_{k-1} (C_{-1} = 0, C_m = N_L), sum n_k = N_L. This
 *    rounds the cumulative counts (each node off by at most half a particle) rather than each
 *    n_k separately: with largest-remainder rounding of the n_k, the ties of an even grid
 *    (all remainders equal) shift the median by up to (m + 1)/4 particles.
 * 3. With c_k the current light count of I_k, |c_k - n_k| randomly chosen particles of I_k
 *    (lights if c_k > n_k, heavies otherwise) switch label, drawn from `rng` (partial
 *    Fisher-Yates; deterministic for a given stream state). This is the least number of
 *    switches that gives every interval its count. If I_k holds fewer than n_k particles, the
 *    counts are made feasible by the average of a forward and a backward greedy pass, so the
 *    excess goes to both neighbours; the result reports it (status adjusted).
 * 5. achieved_icdf = Q_L of the new labels. With feasible counts, each achieved node lies
 *    between the highest light particle below z*_i and the lowest at or above it: the
 *    target is met to within the local spacing of the light particle heights, which is the
 *    resolution of an N_L-point ICDF.
 *
 * Guarantees: the number of light particles is exactly invariant; a target equal to the
 * current ICDF changes no label when the light heights are distinct (ties can cost a swap);
 * `colours` of a rejected call are returned unchanged.
 *
 * Cost: O(N log m) time and O(N) memory, no sort of the heights: a branch-free binary search
 * among the m cuts per particle, then sequential passes for the counts, the switch candidates
 * and the light buckets; the achieved ICDF takes bucket-local minima/maxima (O(N)).
 * Measured CPU time (g++ 12 -O3, demixing target, ~25 % of labels switched): 0.21 ms for
 * N = 1e4 and 2.4 ms for N = 1e5 (ratio 11), i.e. ~2.5 s per coarse step for 1024
 * realizations of 1e5 particles on one rank (~0.3 s at the paper's N = 12,500), against DEM
 * bursts of 2-3e5 time steps per realization. Wall time doubled on a loaded shared core.
 * Reproduce: efdem_unit_tests "[.benchmark]".
 *
 * `moving` (optional, one flag per particle): step 3 draws an interval's switches from its
 * moving particles first and from the still ones only for what is left, so that a bed whose
 * lower part has come to rest is relabelled where it moves (cpi.relabel = moving): the same
 * interval counts, so the same n_changed and the same guarantees; only which particles switch
 * differs. Empty: every candidate alike (the default, as before the option).
 *
 * \pre heights.size() == colours.size(); colours in {kHeavy, kLight};
 *      target_icdf.size() == grid.size(); moving empty or of colours' size.
 */
LiftResult lift_colours(const Eigen::VectorXd& target_icdf, std::span<const double> heights,
                        std::span<const std::uint8_t> colours, const ProbabilityGrid& grid,
                        RandomStream& rng, std::span<const std::uint8_t> moving = {});

}  // namespace efdem::coarse
