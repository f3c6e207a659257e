#include "coarse/equation_free/projective/step_size_controller.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "coarse/equation_free/estimators/slope_pool.hpp"
#include "coarse/equation_free/projective/projective_integrator.hpp"
#include "coarse/equation_free/projective/projective_stability.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {
/// The part of safety x tolerance left for the lift: its expected error, at most half.
double reserved(const StepSizeSettings& s, double lift) {
    return std::min(std::max(lift, 0.0), 0.5 * s.safety * s.tolerance);
}
}  // namespace

Eigen::VectorXd statistical_error(const JumpErrorModel& model, double dt) {
    EFDEM_EXPECTS(dt >= 0.0 && !model.nodes.empty());
    const std::vector<double> w = projection_weights(model.nodes, model.t0, dt);
    if (!model.correction.empty()) {
        const PooledCurvature& b = model.correction;
        EFDEM_EXPECTS(model.nodes.size() == 1 && model.committed.size() == 0 &&
                      b.value.size() == model.nodes.front().se.size());
        const double omega = omega_integral(model.nodes, model.t0, dt);
        const Eigen::ArrayXd se = model.nodes.front().se.array();
        // The growth of the accumulated error's variance (pooled_curvature.hpp): the jump's own
        // variance plus 2 omega kappa, kappa <= 0 where the older bursts' noise is already in
        // the state (the sum is >= 0 up to round-off: a variance after minus one before).
        Eigen::ArrayXd v = w[0] * w[0] * se.square() + omega * omega * b.variance.array() +
                           2.0 * w[0] * omega * b.cov_last().array();
        if (b.committed.size()) v += 2.0 * omega * b.committed.array();
        return v.max(0.0).sqrt().matrix();
    }
    if (model.committed.size() == 0) return statistical_error(model.nodes, w);
    EFDEM_EXPECTS(model.nodes.size() == 1 &&
                  model.committed.size() == model.nodes.front().se.size());
    return charged_error(model.nodes.front().se, model.committed, w[0]);
}

std::string error_parts(double statistical, double truncation, double lift) {
    return fmt::format("statistical {:.3g}, truncation {:.3g}{}", statistical, truncation,
                       lift > 0 ? fmt::format(", lift {:.3g}", lift) : std::string());
}

JumpError jump_error(const JumpErrorModel& model, double dt) {
    JumpError e;
    e.statistical = model.se_scale * rms(statistical_error(model, dt));
    if (std::isfinite(model.curvature))
        e.truncation = model.curvature * omega_integral(model.nodes, model.t0, dt);
    return e;
}

double largest_dt_within(const JumpErrorModel& model, double target, double cap) {
    EFDEM_EXPECTS(target >= 0.0 && cap >= 0.0 && std::isfinite(cap));
    if (jump_error(model, cap).total() <= target) return cap;
    double lo = 0.0, hi = cap;  // error(lo) <= target < error(hi)
    while (hi - lo > 1e-6 * hi) {
        const double mid = 0.5 * (lo + hi);
        (jump_error(model, mid).total() <= target ? lo : hi) = mid;
    }
    return lo;
}

namespace {
// The recorded texts: run files and CSVs hold them, so they never change.
constexpr std::array<std::pair<DtLimit, std::string_view>, 15> kDtLimitText{{
    {DtLimit::none, ""},
    {DtLimit::fixed, "fixed"},
    {DtLimit::first_burst, "first burst"},
    {DtLimit::tolerance, "tolerance"},
    {DtLimit::dt_max, "dt_max"},
    {DtLimit::first_jump_dt, "first jump (cpi.dt)"},
    {DtLimit::first_jump_no_curvature, "first jump (no curvature measured yet)"},
    {DtLimit::growth, "growth"},
    {DtLimit::rejection, "rejection"},
    {DtLimit::end_of_run, "end of run"},
    {DtLimit::below_dt_min, "tolerance below dt_min"},
    {DtLimit::stability, "stability"},
    {DtLimit::fast_transient, "fast transient"},
    {DtLimit::in_phase_wave, "in-phase wave"},
    {DtLimit::jump_until, "cpi.jump_until"},
}};
}  // namespace

std::string_view to_string(DtLimit limit) {
    for (const auto& [l, text] : kDtLimitText)
        if (l == limit) return text;
    return "unknown";
}

std::optional<DtLimit> dt_limit_from_string(std::string_view text) {
    for (const auto& [l, t] : kDtLimitText)
        if (t == text) return l;
    return std::nullopt;
}

StepSizeController::StepSizeController(const StepSizeSetup& setup) : setup_(setup) {
    EFDEM_EXPECTS(std::isfinite(setup.burst) && setup.burst > 0.0);
    if (setup.adaptive) {
        [[maybe_unused]] const StepSizeSettings& c = setup.control;
        EFDEM_EXPECTS(c.tolerance > 0.0 && std::isfinite(c.tolerance));
        EFDEM_EXPECTS(c.dt_min > 0.0 && c.dt_min <= c.dt_max && std::isfinite(c.dt_max));
        EFDEM_EXPECTS(c.safety > 0.0 && c.safety <= 1.0 && c.growth > 1.0 && c.max_rejections >= 0);
    } else {
        EFDEM_EXPECTS(std::isfinite(setup.fixed_dt) && setup.fixed_dt >= 0.0);
    }
}

void StepSizeController::set_tolerance(double tolerance) {
    EFDEM_EXPECTS(std::isfinite(tolerance) && tolerance > 0.0);
    setup_.control.tolerance = tolerance;
}

void StepSizeController::set_burst(double burst, double window) {
    EFDEM_EXPECTS(window > 0.0 && window <= burst);
    setup_.burst = burst;
    setup_.window = window;
}

DtPlan StepSizeController::plan(const PlanInput& in) const {
    DtPlan p;
    const double burst = setup_.burst;
    const double t0 = in.model.t0;
    // The jump is followed by a burst: it must leave room for that burst, and for a whole
    // burst more or none (the rule of end_of_run_jump_limit, one burst later).
    auto end_limit = [&](double dt) {
        return end_of_run_jump_limit(t0 + burst, in.end_time, dt, burst);
    };
    // cpi.jump_until: no jump ends after in.jump_end; from there on each step is a burst of
    // direct simulation, so that what only the DEM does (a bed coming to rest) can happen.
    const double jump_room = in.jump_end - t0;
    if (std::isfinite(in.jump_end) && jump_room <= time_tolerance(in.jump_end)) {
        p.limited_by = DtLimit::jump_until;
        p.message = fmt::format(
            "cpi.jump_until: no jump after t = {:.6g}, bursts of direct "
            "simulation from here",
            in.jump_end);
        return p;
    }
    if (!setup_.adaptive) {
        p.limited_by = DtLimit::fixed;
        p.dt = std::min(setup_.fixed_dt, end_limit(setup_.fixed_dt));
        if (p.dt > jump_room) {
            p.dt = jump_room;
            p.limited_by = DtLimit::jump_until;
        }
        return p;
    }
    const StepSizeSettings& s = setup_.control;
    if (in.hold != DtLimit::none) {  // the slope is a fast transient's or a common wave's, not
                                     // the slow dynamics'
        p.message = in.hold_message + ": one burst of direct simulation";
        p.limited_by = in.hold;
        return p;
    }
    JumpErrorModel model = in.model;
    const double target = s.safety * s.tolerance - reserved(s, in.lift_reserve);
    p.dt_tolerance = largest_dt_within(model, target, s.dt_max);
    model.se_scale = 1.0 / std::sqrt(2.0);
    p.dt_tolerance_2r = largest_dt_within(model, target, s.dt_max);
    model.se_scale = 0.5;
    p.dt_tolerance_4r = largest_dt_within(model, target, s.dt_max);
    model.se_scale = 1.0;  // the realizations this run has

    double dt = p.dt_tolerance;
    p.limited_by = dt >= s.dt_max ? DtLimit::dt_max : DtLimit::tolerance;
    auto limit = [&](double cap, DtLimit why) {
        if (cap < dt) {
            dt = cap;
            p.limited_by = why;
        }
    };
    const bool first_jump = !std::isfinite(state_.dt_last);  // no jump kept yet
    if (std::isfinite(setup_.first_dt) && first_jump)
        limit(setup_.first_dt, DtLimit::first_jump_dt);
    else if (!std::isfinite(model.curvature))
        limit(std::max(s.dt_min, burst), DtLimit::first_jump_no_curvature);
    if (!first_jump) limit(s.growth * state_.dt_last, DtLimit::growth);
    limit(state_.dt_cap, DtLimit::rejection);
    limit(jump_room, DtLimit::jump_until);
    if (setup_.dt_quantum > 0.0 && std::isfinite(dt))
        dt = std::floor(dt / setup_.dt_quantum * (1.0 + 1e-12)) * setup_.dt_quantum;
    const double tol = time_tolerance(in.end_time);
    if (end_limit(dt) <= tol) {  // this step's burst is the run's last: no jump before it
        p.limited_by = DtLimit::end_of_run;
        return p;
    }
    if (dt < s.dt_min * (1.0 - 1e-12) && p.limited_by == DtLimit::jump_until) {
        p.message = fmt::format(
            "cpi.jump_until: the {:.3g} time units left before t = {:.6g} are "
            "less than cpi.dt_min = {:.3g}: one burst of direct simulation",
            jump_room, in.jump_end, s.dt_min);
        return p;
    }
    if (dt < s.dt_min * (1.0 - 1e-12)) {
        const std::string why = p.limited_by == DtLimit::rejection
                                    ? fmt::format(
                                          "the curvature the rejected jump showed allows no DT >= "
                                          "cpi.dt_min = {:.3g} within the "
                                          "tolerance",
                                          s.dt_min)
                                    : fmt::format(
                                          "the tolerance {:.3g} allows DT = {:.3g} < cpi.dt_min = "
                                          "{:.3g} (statistical error of "
                                          "one DT_min jump {:.3g})",
                                          s.tolerance, p.dt_tolerance, s.dt_min,
                                          jump_error(model, s.dt_min).statistical);
        p.message = why + ": one burst of direct simulation instead";
        p.limited_by = DtLimit::below_dt_min;
        return p;
    }
    const double end = end_limit(dt);
    if (end < dt) {
        // The rule leaves room for one more burst; if the tolerance allows reaching the last
        // burst in this jump (less than one burst further), do that instead.
        // Never beyond the cap a rejected jump or a failed lift set: a redo as long as the
        // jump that failed would fail again (a lift that cannot relax its overlaps at this DT
        // was retried without end at the end of a run).
        const double to_last_burst = in.end_time - (t0 + burst);
        dt = to_last_burst > dt && to_last_burst <= p.dt_tolerance && to_last_burst <= state_.dt_cap
                 ? to_last_burst
                 : end;
        if (dt <= tol) return p;  // rounding: nothing left to jump (dt 0)
        p.limited_by = DtLimit::end_of_run;
    }
    // Never a jump the measured transient would be amplified by: shorten until stable.
    // The plan keeps the assessment of the DT taken (or of the last one refused).
    CpiCycle cycle{setup_.estimator, burst, setup_.window, dt,
                   static_cast<int>(model.nodes.size())};
    for (int i = 0; i < 20 && dt > 0.0; ++i) {
        cycle.dt = dt;
        const StabilityAssessment a = assess_stability(in.decay, cycle);
        p.stability = a;
        if (a.stable) break;
        dt = dt * 0.5 >= s.dt_min ? dt * 0.5 : 0.0;
        p.limited_by = DtLimit::stability;
        if (dt == 0.0) p.message = "no DT >= cpi.dt_min is stable: " + a.message;
    }
    p.dt = dt;
    return p;
}

JumpVerdict StepSizeController::judge(double dt, const JumpError& error,
                                      const JumpErrorModel& posterior, bool forced_reject) {
    const StepSizeSettings& s = setup_.control;
    const double e = error.total();
    const bool within = e <= s.tolerance;
    const bool at_floor = dt <= s.dt_min * (1.0 + 1e-12);
    const bool too_many = state_.consecutive_rejections >= s.max_rejections;
    JumpVerdict v;
    v.accepted = !setup_.adaptive || (!forced_reject && (within || at_floor || too_many));
    if (v.accepted) {
        if (setup_.adaptive && !within)
            v.message =
                fmt::format("error {:.3g} = {:.2f} x tolerance kept: {}", e, e / s.tolerance,
                            at_floor ? "DT is at cpi.dt_min" : "too many rejections in a row");
        state_.dt_last = dt;
        state_.dt_cap = std::numeric_limits<double>::infinity();
        state_.consecutive_rejections = 0;
        return v;
    }
    // Rejected: the next step jumps less far, planned with the curvature the burst after the
    // jump showed. A redo that this curvature would not allow even at dt_min is not tried: the
    // next step runs one burst directly (cap 0) instead of a jump known to exceed the tolerance.
    const double redo =
        largest_dt_within(posterior, s.safety * s.tolerance - reserved(s, error.lift), dt);
    state_.dt_cap = forced_reject     ? 0.5 * dt
                    : redo < s.dt_min ? 0.0
                                      : std::max(s.dt_min, std::min(redo, 0.5 * dt));
    ++state_.consecutive_rejections;
    v.message = fmt::format(
        "step rejected{}: error {:.3g} = {:.2f} x tolerance ({}); back to t = {:.6g}, next DT <= "
        "{:.4g}",
        forced_reject ? " (forced)" : "", e, e / s.tolerance,
        error_parts(error.statistical, error.truncation, error.lift), posterior.t0, state_.dt_cap);
    return v;
}

void StepSizeController::jump_failed(double dt) {
    state_.dt_cap = 0.5 * dt;
}

void StepSizeController::direct_burst_done() {
    state_.dt_cap = std::numeric_limits<double>::infinity();
}

}  // namespace efdem::coarse
