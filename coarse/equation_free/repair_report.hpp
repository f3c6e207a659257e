#pragma once
/// \file
/// RepairReport: what a repair hook (ProjectiveIntegrator's RepairHook) did to a projected
/// coarse vector before it was lifted. Generic: the repair itself belongs to the coarse
/// variable (coarse/demixing/monotone_repair.hpp for an ICDF).

#include <functional>
#include <string>

#include <Eigen/Core>

namespace efdem::coarse {

/// What a repair hook did to a projected vector, for the step record and the log (e.g.
/// coarse/demixing/monotone_repair.hpp: isotonic regression and clipping of an ICDF).
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
 * \brief Called on the projected (or perturbed) vector before lifting; may change it in place and
 * reports what it did. A report with feasible == false stops the step before the lift.
 *
 * \code
 * RepairHook clip = [&](Eigen::VectorXd& x) { return repair_monotone(x, z_min, z_max); };
 * \endcode
 */
using RepairHook = std::function<RepairReport(Eigen::VectorXd& projected)>;

}  // namespace efdem::coarse
