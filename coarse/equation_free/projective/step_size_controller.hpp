#pragma once
/// \file
/// The step-size rule of adaptive coarse projective integration (docs/error_control.md): the
/// error a jump of DT adds, from the slope model of multistep_projection.hpp, and the largest
/// DT whose error stays within a target. Times in sqrt(d_p/g); errors RMS over the coarse
/// vector's components (d_p for the ICDF).

#include <limits>
#include <vector>

#include "coarse/equation_free/projective/multistep_projection.hpp"

namespace efdem::coarse {

/// What the error of the next jump depends on.
struct JumpErrorModel {
    /// The method's nodes (q of them: 1 forward Euler, 2 Adams-Bashforth 2), oldest first.
    std::vector<SlopeNode> nodes;
    double t0 = 0.0;  ///< the jump starts here (end of the last burst)
    /// |D|, the noise-free RMS of the q-th divided difference of the slope; NaN while fewer
    /// than q + 1 slopes have been measured (the truncation part is then unknown, counted 0).
    double curvature = std::numeric_limits<double>::quiet_NaN();
    /// Factor on every standard error: 1/sqrt(k) for k times the realizations.
    double se_scale = 1.0;
};

/// The two parts of a jump's error (RMS over components).
struct JumpError {
    double statistical = 0.0;  ///< RMS of sqrt(sum_k W_k^2 se_k^2)
    double truncation = 0.0;   ///< |D| |integral omega|
    double total() const { return statistical + truncation; }
};

/// The error of a jump of `dt` under `model`. \pre dt >= 0, model.nodes non-empty.
JumpError jump_error(const JumpErrorModel& model, double dt);

/// The largest DT in [0, cap] with jump_error(model, DT).total() <= target (the error grows
/// monotonically with DT; bisection to 1e-6 relative). 0 when even tiny jumps exceed it only
/// if target <= 0. \pre target >= 0, cap >= 0 finite.
double largest_dt_within(const JumpErrorModel& model, double target, double cap);

}  // namespace efdem::coarse
