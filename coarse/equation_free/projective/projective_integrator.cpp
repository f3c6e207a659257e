#include "coarse/equation_free/projective/projective_integrator.hpp"

#include <algorithm>
#include <cmath>

#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

std::string_view to_string(StepStatus status) {
    switch (status) {
        case StepStatus::projected:
            return "projected";
        case StepStatus::burst_only:
            return "burst_only";
        case StepStatus::stopped_unstable:
            return "stopped_unstable";
        case StepStatus::too_few_periods:
            return "too_few_periods";
        case StepStatus::invalid_burst:
            return "invalid_burst";
        case StepStatus::infeasible_projection:
            return "infeasible_projection";
        case StepStatus::lift_failed:
            return "lift_failed";
        case StepStatus::rejected:
            return "rejected";
    }
    return "unknown";
}

double end_of_run_jump_limit(double t_after_burst, double t_end, double dt, double burst) {
    if (!std::isfinite(t_end)) return std::numeric_limits<double>::infinity();
    const double left = t_end - t_after_burst;
    const double tol = time_tolerance(t_end);
    if (left <= tol) return 0.0;  // the burst ended the run: what is left is round-off, no jump
    if (left <= dt + tol) return left;
    if (left - dt < burst - tol) return std::max(0.0, left - burst);
    return std::numeric_limits<double>::infinity();
}

double burst_length_to_end(double now, double t_end, double burst) {
    if (!std::isfinite(t_end)) return burst;
    const double left = t_end - now;
    return left < 2.0 * burst - time_tolerance(t_end) ? left : burst;
}

void CoarseStepper::lift_apart([[maybe_unused]] const Eigen::VectorXd& target,
                               [[maybe_unused]] const Eigen::MatrixXd& member_steps,
                               [[maybe_unused]] double new_time) {
    EFDEM_EXPECTS(lifts_apart());
}
void CoarseStepper::keep_state() {
    EFDEM_EXPECTS(can_keep_state());
}
void CoarseStepper::return_to_kept_state() {
    EFDEM_EXPECTS(can_keep_state());
}
void CoarseStepper::confirm_kept_state() {
    EFDEM_EXPECTS(can_keep_state());
}

void ProjectiveIntegrator::restore_state([[maybe_unused]] const IntegratorState& state) {
    EFDEM_EXPECTS(!state.has_value());
}

double ProjectiveIntegrator::jump_limit(double t_after_burst, double dt, double burst) const {
    return end_of_run_jump_limit(t_after_burst, end_time_, dt, burst);
}

}  // namespace efdem::coarse
