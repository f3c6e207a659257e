#pragma once
/// \file
/// Monotone repair of a projected ICDF (physics.md §9 step 1, §11.4): a projected coarse vector
/// X_proj = X + DT s need not be non-decreasing in p, and need not lie inside the heights the
/// particles occupy; lifting needs both.

#include <string>

#include <Eigen/Core>

namespace efdem::coarse {

/// What monotone repair did to a vector, for the step record and the log.
struct RepairReport {
    /// false: the input had non-finite entries and was left untouched (nothing can be lifted).
    bool feasible = true;
    /// The input was not non-decreasing (isotonic regression changed it).
    bool non_monotone = false;
    /// max_i |x_out,i - x_in,i| [same unit as x; d_p for heights].
    double max_adjustment = 0.0;
    /// Nodes moved onto z_min or z_max by clipping.
    int n_clipped = 0;
    /// Empty when nothing was changed; otherwise says what was done and by how much.
    std::string message;

    bool changed() const { return max_adjustment > 0.0; }
};

/**
 * \brief Isotonic regression with equal weights (pool-adjacent-violators), in place.
 *
 * Replaces x by the non-decreasing vector closest to it in the Euclidean norm: adjacent
 * violators are pooled into blocks whose value is the block mean. A non-decreasing input is
 * returned unchanged (bit for bit). O(m). \pre x finite.
 */
void isotonic_regression(Eigen::Ref<Eigen::VectorXd> x);

/**
 * \brief Makes x a valid ICDF target: isotonic regression, then clipping into [z_min, z_max].
 *
 * Clipping the isotonic solution keeps it non-decreasing and gives the Euclidean projection
 * onto {non-decreasing} ∩ [z_min, z_max]^m. [z_min, z_max] is the feasible height range [d_p]
 * (for colour lifting: the lowest and highest particle heights). A non-finite entry makes the
 * input infeasible: x is left untouched and the report says which entry.
 * \pre z_min <= z_max, both finite.
 */
RepairReport repair_monotone(Eigen::VectorXd& x, double z_min, double z_max);

}  // namespace efdem::coarse
