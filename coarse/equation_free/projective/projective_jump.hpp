#pragma once
/// \file
/// The half of an outer step that both projective integrators share: checking the burst, and
/// stability check -> extrapolation from the raw end-of-burst value -> repair -> lift.

#include <limits>
#include <vector>

#include "coarse/equation_free/coarse_stepper.hpp"
#include "coarse/equation_free/projective/projective_integrator.hpp"
#include "coarse/equation_free/projective/projective_stability.hpp"
#include "coarse/equation_free/projective/stability_monitor.hpp"

namespace efdem::coarse {

/**
 * \brief Checks rec.burst and sets rec.t_end and rec.x_end from its last sample.
 *
 * The burst must be non-empty, with strictly increasing times, one finite vector of one size
 * per time, the last sample at `micro_time` (to time_tolerance()), and, if
 * `needs_phase_signal`, one phase value per time. On failure sets rec.status = invalid_burst
 * and rec.message, and returns false.
 */
bool check_burst(ProjectiveStepRecord& rec, double micro_time, bool needs_phase_signal);

/// What project_and_lift() needs besides the record.
struct JumpPlan {
    /// The cycle as planned (cycle.dt is ignored: the candidates give DT).
    CpiCycle cycle;
    /// DT values in order of preference: the planned one first, then the reductions the
    /// halve_step policy may take, ending with 0.
    std::vector<double> dt_candidates;
    /// No candidate larger than this is taken (the end of the run); the record says so.
    double dt_max = std::numeric_limits<double>::infinity();
    DecayRateEstimate decay;
    StabilityPolicy policy = StabilityPolicy::warn;
};

/**
 * \brief Chooses DT by the stability policy, extrapolates X_proj = X(t_end) + DT s from the
 *        raw end-of-burst value (physics.md §10), applies `repair`, and lifts to X_proj at
 *        t_end + DT.
 *
 * Fills rec.dt_requested, dt, stability, x_projected, repair, lifted, status and message.
 * With DT = 0 (planned or reduced) nothing is lifted (status burst_only). When the jump is
 * refused (infeasible_projection), x_projected holds the rejected projection for diagnosis.
 * \pre rec.slope and rec.x_end set, of one size; plan.dt_candidates non-empty, each >= 0.
 */
void project_and_lift(ProjectiveStepRecord& rec, CoarseStepper& stepper, const JumpPlan& plan,
                      const RepairHook& repair);

/**
 * \brief The checks every projected vector passes before a lift: finite, then `repair` (may be
 *        empty). Sets rec.x_projected (the rejected vector, for diagnosis, when it fails) and
 *        rec.repair; on failure rec.status = infeasible_projection with a message, and returns
 *        false (nothing may be lifted).
 */
bool repair_projection(ProjectiveStepRecord& rec, Eigen::VectorXd& x, const RepairHook& repair);

/// Appends `note` to rec.message ("; "-separated).
void append_message(ProjectiveStepRecord& rec, const std::string& note);

}  // namespace efdem::coarse
