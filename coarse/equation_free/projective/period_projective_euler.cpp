#include "coarse/equation_free/projective/period_projective_euler.hpp"

#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "coarse/equation_free/projective/projective_jump.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

/// Period of the post-healing phase signal (an empty estimate if it holds < 2 samples).
PeriodEstimate post_healing_period(const BurstSamples& b, double t_window,
                                   const PeriodSettings& settings) {
    const std::size_t first = first_sample_at_or_after(b.t, t_window);
    if (b.t.size() < first + 2) {
        PeriodEstimate none;
        none.message = fmt::format("{} sample(s) after healing (t >= {:.6g}): no period",
                                   b.t.size() - first, t_window);
        return none;
    }
    return estimate_period(std::span(b.t).subspan(first), std::span(b.phase_signal).subspan(first),
                           settings);
}

}  // namespace

PeriodProjectiveEuler::PeriodProjectiveEuler(const PeriodProjectiveEulerSettings& settings,
                                             RepairHook repair, const PeriodSettings& period)
    : settings_(settings), repair_(std::move(repair)), period_(period) {
    EFDEM_EXPECTS(std::isfinite(settings.burst.healing) && settings.burst.healing >= 0.0);
    EFDEM_EXPECTS(std::isfinite(settings.burst.window) && settings.burst.window > 0.0);
    EFDEM_EXPECTS(settings.periods_per_step >= 0);
    EFDEM_EXPECTS(std::isfinite(settings.max_extension) && settings.max_extension >= 0.0);
    EFDEM_EXPECTS(std::isfinite(settings.extension_step) && settings.extension_step > 0.0);
    EFDEM_EXPECTS(period.min_periods >= 2);
}

ProjectiveStepRecord PeriodProjectiveEuler::step(CoarseStepper& stepper) {
    ProjectiveStepRecord rec;
    rec.t_start = stepper.time();
    rec.healing = settings_.burst.healing;
    rec.burst_length = settings_.burst.healing + settings_.burst.window;
    stepper.run(rec.burst_length, rec.burst);
    const double t_window = rec.t_start + settings_.burst.healing;

    double extension = 0.0;
    PeriodEstimate period;
    for (;;) {
        if (!check_burst(rec, stepper.time(), true)) return rec;
        period = post_healing_period(rec.burst, t_window, period_);
        if (period.ok()) break;
        const double more = std::min(settings_.extension_step, settings_.max_extension - extension);
        if (more <= time_tolerance(settings_.max_extension)) {
            rec.status = StepStatus::too_few_periods;
            rec.period = period.period;
            append_message(rec, fmt::format("{} (burst extended by {:.6g}, the maximum)",
                                            period.message, extension));
            return rec;
        }
        stepper.run(more, rec.burst);
        extension += more;
        rec.burst_length += more;
    }
    if (extension > 0.0)
        append_message(rec, fmt::format("burst extended by {:.6g} to see {} periods", extension,
                                        period.n_periods));
    rec.period = period.period;

    const std::size_t first = first_sample_at_or_after(rec.burst.t, t_window);
    const auto t = std::span<const double>(rec.burst.t).subspan(first);
    const auto x = std::span<const Eigen::VectorXd>(rec.burst.x).subspan(first);
    const SlopeEstimate slope = period_mean_slope(t, x, rec.period, rec.t_end);
    if (!slope.ok) {
        rec.status = StepStatus::invalid_burst;
        append_message(rec, slope.message);
        return rec;
    }
    rec.slope = slope.slope;
    // Each member's own period means over the ensemble-mean period T: the same linear
    // estimator as the ensemble slope, so the members' slopes average to it.
    if (rec.burst.members.size() == rec.burst.t.size()) {
        const auto members = std::span<const Eigen::MatrixXd>(rec.burst.members).subspan(first);
        rec.slope_standard_error =
            slope_standard_error(member_period_mean_slopes(t, members, rec.period, rec.t_end));
    }
    rec.window = 2.0 * rec.period;

    JumpPlan plan;
    plan.cycle = {SlopeEstimator::period_mean, rec.t_end - rec.t_start, rec.period, 0.0};
    plan.policy = settings_.burst.stability;
    plan.decay = estimate_decay_rate_periodic(t, x, rec.period, t_window, rec.t_end);
    for (int k = settings_.periods_per_step; k > 0; k /= 2)
        plan.dt_candidates.push_back(k * rec.period);
    plan.dt_candidates.push_back(0.0);
    // A burst is at least healing + window (its extensions are not known in advance).
    plan.dt_max = jump_limit(rec.t_end, plan.dt_candidates.front(),
                             settings_.burst.healing + settings_.burst.window);
    project_and_lift(rec, stepper, plan, repair_);
    rec.periods_per_step = static_cast<int>(std::lround(rec.dt / rec.period));
    return rec;
}

}  // namespace efdem::coarse
