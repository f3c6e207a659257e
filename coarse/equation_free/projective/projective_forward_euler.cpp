#include "coarse/equation_free/projective/projective_forward_euler.hpp"

#include <cmath>
#include <utility>

#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "coarse/equation_free/projective/projective_jump.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

ProjectiveForwardEuler::ProjectiveForwardEuler(const ProjectiveEulerSettings& settings,
                                               RepairHook repair)
    : settings_(settings), repair_(std::move(repair)) {
    EFDEM_EXPECTS(std::isfinite(settings.burst.healing) && settings.burst.healing >= 0.0);
    EFDEM_EXPECTS(std::isfinite(settings.burst.window) && settings.burst.window > 0.0);
    EFDEM_EXPECTS(std::isfinite(settings.dt) && settings.dt >= 0.0);
    EFDEM_EXPECTS(settings.max_halvings >= 0);
}

ProjectiveStepRecord ProjectiveForwardEuler::step(CoarseStepper& stepper) {
    ProjectiveStepRecord rec;
    rec.t_start = stepper.time();
    rec.healing = settings_.burst.healing;
    rec.dt_requested = settings_.dt;
    rec.burst_length = settings_.burst.healing + settings_.burst.window;
    stepper.run(rec.burst_length, rec.burst);
    if (!check_burst(rec, stepper.time(), false)) return rec;

    const double t_window = rec.t_start + settings_.burst.healing;
    const SlopeEstimate slope = least_squares_slope(rec.burst.t, rec.burst.x, t_window);
    if (!slope.ok) {
        rec.status = StepStatus::invalid_burst;
        append_message(rec, slope.message);
        return rec;
    }
    rec.slope = slope.slope;
    rec.slope_standard_error =
        member_slope_standard_error(rec.burst.t, rec.burst.members, t_window);
    rec.window = slope.t_last - slope.t_first;

    JumpPlan plan;
    plan.cycle = {SlopeEstimator::least_squares, rec.t_end - rec.t_start, rec.window, 0.0};
    plan.policy = settings_.burst.stability;
    plan.decay = estimate_decay_rate(rec.burst.t, rec.burst.x, t_window);
    for (int i = 0; i <= settings_.max_halvings; ++i)
        plan.dt_candidates.push_back(std::ldexp(settings_.dt, -i));
    plan.dt_candidates.push_back(0.0);
    plan.dt_max = jump_limit(rec.t_end, settings_.dt, rec.burst_length);
    project_and_lift(rec, stepper, plan, repair_);
    return rec;
}

}  // namespace efdem::coarse
