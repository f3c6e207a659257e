#pragma once
/// \file
/// Is there a transient after a lift? The evidence behind cpi.healing_auto: a lift puts the
/// micro state where no trajectory of the slow dynamics would (a recolouring, not a relaxed bed),
/// and the healing at the start of every burst is there to let that relax before the slope is
/// measured. If the burst shows no such relaxation beyond the realizations' noise, the healing
/// is slope information thrown away (docs/error_control.md §7).
///
/// The test: every realization's least-squares line over the burst's second half, extrapolated
/// back over its first half; the realizations' mean residual there per component (a relaxing
/// transient bends the early samples away from the late line) against the realizations' scatter
/// (mean_significance.hpp). Slow curvature of the dynamics over half a burst also counts, which
/// errs on the side of keeping the healing.

#include <span>
#include <string>

#include <Eigen/Core>

#include "coarse/equation_free/estimators/mean_significance.hpp"

namespace efdem::coarse {

/// The realizations' residuals of the burst's first half against their own late lines.
/// Not measured with fewer than 2 realizations, or fewer than 2 samples in either half of
/// (t_lift, t_last] (a sample at t_lift itself is the lifted state, left out).
/// \pre t strictly increasing; members one R x dim matrix per sample.
MeanSignificance post_lift_transient(std::span<const double> t,
                                     std::span<const Eigen::MatrixXd> members, double t_lift);

}  // namespace efdem::coarse
