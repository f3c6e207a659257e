#include "coarse/equation_free/projective/projective_jump.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

void append_message(ProjectiveStepRecord& rec, const std::string& note) {
    if (note.empty()) return;
    rec.message += rec.message.empty() ? note : "; " + note;
}

bool check_burst(ProjectiveStepRecord& rec, double micro_time, bool needs_phase_signal) {
    const BurstSamples& b = rec.burst;
    auto fail = [&](const std::string& why) {
        rec.status = StepStatus::invalid_burst;
        append_message(rec, "invalid burst: " + why);
        return false;
    };
    if (b.t.empty()) return fail("the coarse stepper returned no samples");
    if (b.x.size() != b.t.size())
        return fail(fmt::format("{} sample times but {} coarse vectors", b.t.size(), b.x.size()));
    if (needs_phase_signal && b.phase_signal.size() != b.t.size())
        return fail(fmt::format(
            "the DT = k T integrator needs one phase-signal value per sample; got {} for {} "
            "samples",
            b.phase_signal.size(), b.t.size()));
    for (std::size_t k = 0; k < b.t.size(); ++k) {
        if (!std::isfinite(b.t[k]) || (k > 0 && !(b.t[k] > b.t[k - 1])))
            return fail(fmt::format("sample times are not strictly increasing at sample {}", k));
        if (b.x[k].size() != b.x.front().size())
            return fail(fmt::format("sample {} has {} components, sample 0 has {}", k,
                                    b.x[k].size(), b.x.front().size()));
        if (!b.x[k].allFinite())
            return fail(fmt::format("sample {} (t = {:.6g}) is not finite", k, b.t[k]));
        if (needs_phase_signal && !std::isfinite(b.phase_signal[k]))
            return fail(fmt::format("phase signal at sample {} is not finite", k));
    }
    if (std::abs(b.t.back() - micro_time) > time_tolerance(micro_time))
        return fail(fmt::format(
            "the last sample is at t = {:.9g} but the burst ended at t = {:.9g}; the stepper "
            "must sample at the end of each run (the jump starts there)",
            b.t.back(), micro_time));
    rec.t_end = b.t.back();
    rec.x_end = b.x.back();
    return true;
}

bool repair_projection(ProjectiveStepRecord& rec, Eigen::VectorXd& x, const RepairHook& repair) {
    rec.x_projected = x;  // kept for diagnosis if the jump is refused below
    if (!x.allFinite()) {
        rec.status = StepStatus::infeasible_projection;
        append_message(
            rec, fmt::format("projected state X(t_end) + {:.6g} s is not finite; nothing lifted",
                             rec.dt));
        return false;
    }
    if (repair) {
        rec.repair = repair(x);
        append_message(rec, rec.repair.message);
        if (!rec.repair.feasible) {
            rec.status = StepStatus::infeasible_projection;
            append_message(rec, "repair hook rejected the projected state; nothing lifted");
            return false;
        }
    }
    rec.x_projected = x;
    return true;
}

void project_and_lift(ProjectiveStepRecord& rec, CoarseStepper& stepper, const JumpPlan& plan,
                      const RepairHook& repair) {
    EFDEM_EXPECTS(!plan.dt_candidates.empty() && plan.dt_candidates.front() >= 0.0);
    EFDEM_EXPECTS(rec.slope.size() == rec.x_end.size());
    CpiCycle cycle = plan.cycle;
    std::vector<double> candidates = plan.dt_candidates;
    for (double& c : candidates) c = std::min(c, plan.dt_max);
    rec.dt_requested = plan.dt_candidates.front();
    cycle.dt = rec.dt = candidates.front();
    if (rec.dt < rec.dt_requested)
        append_message(rec, fmt::format("DT shortened from {:.6g} to {:.6g}: the run ends soon",
                                        rec.dt_requested, rec.dt));
    rec.stability = assess_stability(plan.decay, cycle);
    rec.x_projected = rec.x_end;

    if (!rec.stability.stable) {
        switch (plan.policy) {
            case StabilityPolicy::warn:
                append_message(rec, "stability warning (step taken): " + rec.stability.message);
                break;
            case StabilityPolicy::stop:
                rec.dt = 0.0;
                rec.status = StepStatus::stopped_unstable;
                append_message(rec, "step stopped before the jump: " + rec.stability.message);
                return;
            case StabilityPolicy::halve_step:
                rec.dt = 0.0;
                for (std::size_t i = 1; i < candidates.size(); ++i) {
                    cycle.dt = candidates[i];
                    if (std::abs(cpi_amplification(cycle, rec.stability.rate)) <= 1.0) {
                        rec.dt = cycle.dt;
                        break;
                    }
                }
                append_message(rec, fmt::format("DT reduced from {:.6g} to {:.6g}: {}",
                                                rec.dt_requested, rec.dt, rec.stability.message));
                break;
        }
    }
    if (rec.dt == 0.0) {
        rec.status = StepStatus::burst_only;
        return;
    }

    Eigen::VectorXd x = rec.x_end + rec.dt * rec.slope;
    if (!repair_projection(rec, x, repair)) return;
    stepper.lift(rec.x_projected, rec.t_end + rec.dt);
    rec.lifted = true;
    rec.status = StepStatus::projected;
}

}  // namespace efdem::coarse
