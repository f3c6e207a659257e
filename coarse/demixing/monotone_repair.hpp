#pragma once
/// \file
/// Monotone repair of a projected ICDF (physics.md §9 step 1, §11.4): a projected coarse vector
/// X_proj = X + DT s need not be non-decreasing in p, and need not lie inside the heights the
/// particles occupy; lifting needs both.

#include <string>

#include <Eigen/Core>

#include "coarse/equation_free/repair_report.hpp"

namespace efdem::coarse {

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
