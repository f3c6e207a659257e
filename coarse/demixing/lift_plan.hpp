#pragma once
/// \file
/// The first steps every lifting to a target ICDF shares (physics.md §9 steps 1-2): the target
/// repaired into a non-decreasing ICDF inside the height range, the heights cut at its nodes
/// into intervals, and the observed count each interval must hold. Colour lifting then switches
/// labels inside each interval (colour_lifting.hpp); position lifting moves particles between
/// intervals (position_lifting.hpp).

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "coarse/demixing/monotone_repair.hpp"
#include "coarse/demixing/probability_grid.hpp"

namespace efdem::coarse {

/// Species labels ("colours") as the liftings read and write them: the observed species (whose
/// ICDF is the coarse variable) is kLight, the other kHeavy, whatever their densities or sizes.
inline constexpr std::uint8_t kHeavy = 0;
inline constexpr std::uint8_t kLight = 1;

/// How a target whose counts some interval cannot hold (more observed particles asked for than
/// it has particles) is made feasible: where the excess goes.
enum class CountPlan {
    /// A forward pass pushes any excess up, a backward pass down, the floor of their mean splits
    /// it between the neighbours (the paper's lift; position lifting).
    halves,
    /// The feasible counts nearest the wanted ones: the fewest observed particles placed across
    /// cuts other than asked, then the least squares (an excess that can go either way is split).
    /// In a segregated bed, where every interval above a cut is
    /// full, `halves` moves half of a short interval's excess down through every full interval
    /// below it (each node off by it: a lift that mixes the bed); `nearest` puts it into the one
    /// interval with room. The colour lift's default (Relabel::at_nodes).
    nearest,
};

struct LiftPlan {
    /// Non-empty when no lift can be made (non-finite target or heights, no observed particle,
    /// all heights equal); then nothing below is set.
    std::string error;
    /// The target actually aimed at: after monotone repair and clipping into the height range.
    Eigen::VectorXd target;
    RepairReport repair;
    std::int64_t n_observed = 0;
    /// Interval of each particle: the number of cuts (target nodes) at or below its height;
    /// interval k of m + 1 is [z*_{k-1}, z*_k).
    std::vector<std::uint32_t> interval;
    std::vector<std::int64_t> population;    ///< particles per interval (m + 1)
    std::vector<std::int64_t> observed_now;  ///< observed particles per interval (m + 1)
    /// Observed count below each cut the target asks for: B_0 = 0, B_i = round(p_{i-1} N_L)
    /// (count_below_quantile), B_{m+1} = N_L (m + 2 entries).
    std::vector<std::int64_t> wanted;
    /// `wanted` made feasible for the populations (0 <= B_{k+1} - B_k <= population_k), by the
    /// plan's CountPlan. Equal to `wanted` when every interval can take its count.
    std::vector<std::int64_t> below;
    /// Intervals that held fewer particles than their wanted observed count.
    int n_short_intervals = 0;

    /// Observed particles interval k must gain (negative: lose) to hold its feasible count.
    std::int64_t gain(std::size_t k) const { return below[k + 1] - below[k] - observed_now[k]; }
    /// The largest |below - wanted| over the cuts: how many particles a node's count is off
    /// because some interval was too small (0 when every interval could take its count).
    std::int64_t shortfall() const;
    /// "n interval(s) held fewer particles than their <count_name> count[; <remedy>] (a node's
    /// count off by up to s)", or empty when every interval could take its count: the one
    /// wording of the liftings' messages.
    std::string shortage(std::string_view count_name, std::string_view remedy) const;
};

/**
 * \brief The repaired target and the interval counts for lifting `colours` (kLight = observed)
 *        at `heights` to `target_icdf`.
 *
 * Cost: O(N log m), one sequential pass over the particles: a branch-free binary search among
 * the m cuts per particle (cuts_at_or_below); with CountPlan::nearest and a target some
 * interval cannot hold, O(m N_L) more for the counts.
 * \pre heights.size() == colours.size(); colours in {kHeavy, kLight};
 *      target_icdf.size() == grid.size().
 */
LiftPlan plan_lift(const Eigen::VectorXd& target_icdf, std::span<const double> heights,
                   std::span<const std::uint8_t> colours, const ProbabilityGrid& grid,
                   CountPlan counts = CountPlan::halves);

/// The particles of each of the plan's m + 1 intervals, in index order: one sequential pass.
/// \pre plan without error.
std::vector<std::vector<std::size_t>> particles_by_interval(const LiftPlan& plan);

/// Q of the heights of the particles labelled kLight, on the grid [d_p].
/// \pre heights.size() == colours.size(); at least one kLight.
Eigen::VectorXd observed_icdf(std::span<const double> heights,
                              std::span<const std::uint8_t> colours, const ProbabilityGrid& grid);

/// Number of cuts at or below z (the cuts sorted, m >= 1): a binary search whose halving step
/// compiles to a conditional move (Khuong & Morin 2017), ~10 ns for m = 19 against ~30 ns for
/// std::upper_bound, whose branches on random heights the CPU cannot predict.
std::uint32_t cuts_at_or_below(std::span<const double> cuts, double z);

}  // namespace efdem::coarse
