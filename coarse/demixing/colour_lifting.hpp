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

/// Which particles of a height interval switch label, and where a short interval's excess goes.
enum class Relabel {
    /// Those that define each node of the ICDF are chosen to meet its target (node_pins.hpp);
    /// the rest at random. A few more switches than `random`; the nodes land within the gaps
    /// of all particles, not of the observed ones, and a short interval's excess is placed
    /// next to the cut rather than anywhere in its neighbour. The counts: the feasible ones
    /// nearest the target's (CountPlan::nearest), so a segregated bed is not mixed to place it.
    at_nodes,
    /// All at random: the fewest switches (physics.md §9, the paper's); the counts by
    /// CountPlan::halves.
    random,
};

/// Which of an interval's candidates switch first (cpi.relabel). The count each interval switches
/// is the same whatever the order; within one preference class the draw is uniform.
struct SwitchOrder {
    enum class By {
        any,     ///< every candidate alike (`values` unused)
        moving,  ///< `values` are flags: the moving particles (1) first, the still ones after
        /// `values` count each particle's light neighbours (light_neighbours.hpp): a heavy one
        /// with more of them turns light first, a light one with fewer turns heavy first, so a
        /// lift adds lights to the clusters a direct bed grows and takes away its isolated ones
        /// (bench/results/lift_clusters.md)
        light_neighbours,
        /// `values` count light neighbours as for light_neighbours: the heavies turned light are
        /// drawn with weights that give them the distribution of light-neighbour counts the
        /// lights of their run of particles have (the new lights stand among lights as the
        /// interval's lights do, neither alone nor in denser clusters); the lights turned heavy
        /// at random (a uniform sample of the lights keeps their distribution)
        like_lights,
        /// like_lights' draw of the heavies turned light, light_neighbours' order of the lights
        /// turned heavy (the fewest light neighbours first): a lift that moves lights up (a
        /// CPI jump's, its lower intervals losing lights) removes the lone ones and leaves the
        /// clusters whole, and adds lights as the interval's lights stand
        keep_clusters,
    };
    By by = By::any;
    std::span<const std::uint8_t> values;  ///< one per particle, unless `by` is any

    /// Whether `by` reads light-neighbour counts (else moving flags, or nothing).
    static constexpr bool reads_light_neighbours(By by) {
        return by == By::light_neighbours || by == By::like_lights || by == By::keep_clusters;
    }
    /// Whether `by` draws the heavies it turns light by weight (switch_like_lights).
    static constexpr bool draws_like_lights(By by) {
        return by == By::like_lights || by == By::keep_clusters;
    }
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
 *        1-3 and 5): the interval counts with the fewest switches (random), or with the
 *        particles defining each node chosen to meet it (at_nodes, the default).
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
 * 3. `relabel` = random: with c_k the current light count of I_k, |c_k - n_k| randomly chosen
 *    particles of I_k (lights if c_k > n_k, heavies otherwise) switch label, drawn from `rng`
 *    (partial Fisher-Yates; deterministic for a given stream state). This is the least number
 *    of switches that gives every interval its count. If I_k holds fewer than n_k particles, the
 *    counts are made feasible by the average of a forward and a backward greedy pass, so the
 *    excess goes to both neighbours; the result reports it (status adjusted).
 * 4. `relabel` = at_nodes (the default): the same feasible counts, but first the particles that
 *    hold each node's defining ranks are chosen to meet its target (pin_node_ranks, among the
 *    particles of the interval nearest the cut and its nearest lights); the runs of particles
 *    between and beyond an interval's pins then take their light counts with the fewest random
 *    switches. Each node lands within the local spacing of all particles rather than of the
 *    light ones, and a node whose count was shifted by a short interval is pinned next to its
 *    cut; a target equal to the current ICDF still changes no label (its current pair is exact).
 *    Measured on the demo bed's first jump (4 realizations of 1,000 spheres): RMS lift error
 *    of the ensemble mean 0.067 -> 0.033 d_p, 48-72 -> 98-108 labels switched per realization.
 * 5. achieved_icdf = Q_L of the new labels. With feasible counts, each achieved node lies
 *    between the highest light particle below z*_i and the lowest at or above it: the
 *    target is met to within the local spacing of the light particle heights, which is the
 *    resolution of an N_L-point ICDF. at_nodes: within the gap of all particles around the cut
 *    (tests/coarse/test_colour_lifting.cpp).
 *
 * Guarantees: the number of light particles is exactly invariant; a target equal to the
 * current ICDF changes no label when the light heights are distinct (ties can cost a swap);
 * `colours` of a rejected call are returned unchanged.
 *
 * Cost, random: O(N log m) time and O(N) memory, no sort of the heights: a branch-free binary
 * search among the m cuts per particle, then sequential passes for the counts, the switch
 * candidates and the light buckets; the achieved ICDF takes bucket-local minima/maxima (O(N)).
 * at_nodes adds a sort of each interval's particles, O(N log(N/m)). Measured CPU time (g++ 12
 * -O3, AMD EPYC, demixing target, ~25 % of labels switched), random / at_nodes: 0.16 / 0.80 ms
 * for N = 1e4 and 1.8 / 11 ms for N = 1e5, i.e. at_nodes ~11 s per coarse step for 1024
 * realizations of 1e5 particles on one rank (~1.4 s at the paper's N = 12,500), against DEM
 * bursts of 2-3e5 time steps per realization (hours). Wall time doubled on a loaded shared core.
 * Reproduce: efdem_unit_tests "[.benchmark]".
 *
 * `order` (SwitchOrder): which candidates steps 3 and 4 draw an interval's (or a run's) switches
 * from first. `moving`: the moving particles first and the still ones only for what is left, so
 * that a bed whose lower part has come to rest is relabelled where it moves (cpi.relabel =
 * moving); at_nodes pins a still particle only if it is already light (or none other is in
 * reach). `light_neighbours`: heavies with the most light neighbours turn light first, lights
 * with the fewest turn heavy first (the pins as with `any`). `like_lights`: heavies drawn to turn
 * light with the weights that match their light-neighbour counts to the lights' (Efraimidis-
 * Spirakis keys), lights at random. The same interval counts whatever
 * the order, so the same n_changed and the same guarantees; only which particles switch differs.
 *
 * \pre heights.size() == colours.size(); colours in {kHeavy, kLight};
 *      target_icdf.size() == grid.size(); order.values of colours' size unless order.by is any.
 */
LiftResult lift_colours(const Eigen::VectorXd& target_icdf, std::span<const double> heights,
                        std::span<const std::uint8_t> colours, const ProbabilityGrid& grid,
                        RandomStream& rng, SwitchOrder order = {},
                        Relabel relabel = Relabel::at_nodes);

}  // namespace efdem::coarse
