#include "coarse/equation_free/projective/multistep_projective_integrator.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <utility>

#include <fmt/format.h>

#include "coarse/equation_free/estimators/mean_significance.hpp"
#include "coarse/equation_free/estimators/phase_drift.hpp"
#include "coarse/equation_free/estimators/post_lift_transient.hpp"
#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "coarse/equation_free/projective/projective_jump.hpp"
#include "coarse/equation_free/projective/step_size_controller.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

/// The ensemble's slope (fitted as `fit` says) over the first n samples of a burst from t_a on,
/// its members' own slopes over the same window (R x dim) and the standard error those give
/// (both empty when the burst has no members or the slope failed).
struct WindowFit {
    SlopeEstimate slope;
    Eigen::MatrixXd member_slopes;
    Eigen::VectorXd se;
};

WindowFit fit_window(SlopeFit fit, const BurstSamples& b, double t_a, std::size_t n) {
    const std::span<const double> t(b.t.data(), n);
    WindowFit f;
    f.slope = window_slope(fit, t, std::span<const Eigen::VectorXd>(b.x.data(), n), t_a);
    if (f.slope.ok && b.members.size() == b.t.size()) {
        f.member_slopes = member_window_slopes(
            fit, t, std::span<const Eigen::MatrixXd>(b.members.data(), n), t_a);
        f.se = slope_standard_error(f.member_slopes);
    }
    return f;
}

/// The slope node of a burst's samples in [t_a, t_b). False when the window holds too few
/// samples or no members.
bool window_node(SlopeFit fit, const BurstSamples& b, double t_a, double t_b, SlopeNode& out) {
    const double eps = 1e-9 * std::max(1.0, std::abs(t_b));
    const auto n = static_cast<std::size_t>(std::lower_bound(b.t.begin(), b.t.end(), t_b - eps) -
                                            b.t.begin());  // samples before t_b
    WindowFit f = fit_window(fit, b, t_a, n);
    if (!f.slope.ok || f.se.size() != f.slope.slope.size()) return false;
    out = SlopeNode{f.slope.t_mean, std::move(f.slope.slope), std::move(f.se)};
    return true;
}

}  // namespace

MultistepProjectiveIntegrator::MultistepProjectiveIntegrator(const MultistepSettings& settings,
                                                             RepairHook repair)
    : settings_(settings),
      repair_(std::move(repair)),
      controller_(StepSizeSetup{.control = settings.control,
                                .adaptive = settings.adaptive,
                                .fixed_dt = settings.dt,
                                .first_dt = settings.first_dt,
                                .dt_quantum = settings.dt_quantum,
                                .burst = settings.burst.healing + settings.burst.window,
                                .window = settings.burst.window,
                                .estimator = settings.slope_fit == SlopeFit::increment
                                                 ? SlopeEstimator::increment
                                                 : SlopeEstimator::least_squares}),
      pool_(std::max<std::size_t>(settings.pool, 1)),
      healing_(settings.burst.healing),
      window_(settings.burst.window) {
    EFDEM_EXPECTS(std::isfinite(settings.burst.healing) && settings.burst.healing >= 0.0);
    EFDEM_EXPECTS(std::isfinite(settings.burst.window) && settings.burst.window > 0.0);
    EFDEM_EXPECTS(settings.steps == 1 || settings.steps == 2);
    EFDEM_EXPECTS(settings.pool >= 1);
    EFDEM_EXPECTS(settings.slope == SlopeSource::burst || settings.steps == 1);
    EFDEM_EXPECTS(!settings.healing_auto ||
                  (settings.healing_min >= 0.0 && settings.healing_min <= settings.burst.healing));
    EFDEM_EXPECTS(!settings.window_auto || settings.slope_fit == SlopeFit::least_squares);
    EFDEM_EXPECTS(!settings.window_auto ||
                  (settings.adaptive && settings.window_min > 0.0 &&
                   settings.window_min <= settings.window_max && settings.dt_quantum > 0.0));
    EFDEM_EXPECTS(std::isnan(settings.accuracy) || settings.adaptive);
    if (!std::isnan(settings.accuracy)) budget_.emplace(settings.accuracy);
}

double MultistepProjectiveIntegrator::drift_rate() const {
    if (budget_ && budget_->ready()) return budget_->budget() / burst_length();
    return settings_.drift_rate;
}

double MultistepProjectiveIntegrator::window() const {
    if (settings_.window_auto) return window_;
    return settings_.burst.healing + settings_.burst.window - healing_;
}

void MultistepProjectiveIntegrator::judge_window(const Measured& m, ControllerRecord& c) {
    if (!settings_.window_auto) return;
    if (m.noise.measured) {
        c.window_noise_ratio = m.noise.ratio;
        c.window_noise_correlation = m.noise.correlation;
        ++noise_measurements_;
        const int k = std::min(noise_measurements_, MultistepSettings::window_evidence);
        fast_time2_ = noise_measurements_ == 1
                          ? m.noise.fast_time2
                          : fast_time2_ + (m.noise.fast_time2 - fast_time2_) / k;
    }
    const double step = settings_.dt_quantum, hi = settings_.window_max, lo = settings_.window_min;
    // No evidence yet: the configured window (within the bounds).
    window_ = noise_measurements_ == 0
                  ? std::clamp(window_, lo, hi)
                  : efficient_window(healing_, fast_time2_,
                                     MultistepSettings::window_inefficiency_limit, lo, hi, step);
    // A wave of the ensemble mean biases a slope over a part of its period: whole periods, at
    // least two (on the sampling grid, rounded up), as far as cpi.window_max allows.
    if (std::isfinite(m.wave_period)) {
        const double periods = std::max(2.0, std::ceil(window_ / m.wave_period - 1e-9));
        window_ = std::min(hi, std::ceil(periods * m.wave_period / step - 1e-9) * step);
    }
    c.window_next = window_;
    controller_.set_burst(burst_length(), window_);
}

void MultistepProjectiveIntegrator::judge_healing(const BurstSamples& burst, double t_lift,
                                                  ControllerRecord& c) {
    if (!settings_.healing_auto) return;
    const MeanSignificance e = post_lift_transient(burst.t, burst.members, t_lift);
    c.transient = e.statistic;
    c.transient_threshold = e.threshold;
    if (!e.measured) return;
    // A transient measured: the whole healing; none: the shortest (its lower bound).
    healing_ = e.resolved ? settings_.burst.healing : settings_.healing_min;
}

std::string_view MultistepProjectiveIntegrator::name() const {
    if (settings_.steps == 2)
        return settings_.adaptive ? "adaptive_adams_bashforth2" : "projective_adams_bashforth2";
    return settings_.adaptive ? "adaptive_forward_euler" : "projective_forward_euler_multistep";
}

bool MultistepProjectiveIntegrator::measure_burst(CoarseStepper& stepper, ProjectiveStepRecord& rec,
                                                  Measured& out, double length) const {
    const double t_start = stepper.time();
    if (!(length > 0.0)) length = burst_length();
    rec.burst = BurstSamples{};
    rec.burst_length = length;
    stepper.run(length, rec.burst);
    // check_burst() sets rec.t_end/x_end to the burst's end; rec keeps the jump origin there.
    const double origin_t = rec.t_end;
    Eigen::VectorXd origin_x = std::move(rec.x_end);
    const bool valid = check_burst(rec, stepper.time(), false);
    out.t_end = rec.t_end;
    out.x_end = std::move(rec.x_end);
    rec.t_end = origin_t;
    rec.x_end = std::move(origin_x);
    if (!valid) return false;
    const double t_window = t_start + length - window();  // the last `window` of the burst
    WindowFit fit = fit_window(settings_.slope_fit, rec.burst, t_window, rec.burst.t.size());
    const SlopeEstimate& slope = fit.slope;
    if (!slope.ok) {
        rec.status = StepStatus::invalid_burst;
        append_message(rec, slope.message);
        return false;
    }
    out.node.slope = slope.slope;
    out.node.se = std::move(fit.se);
    out.realizations =
        rec.burst.members.empty() ? 0 : static_cast<int>(rec.burst.members.front().rows());
    if (out.node.se.size() != slope.slope.size()) {
        if (settings_.adaptive) {
            rec.status = StepStatus::invalid_burst;
            append_message(rec,
                           "the error controller needs every realization's own slope (at least two "
                           "realizations, an observable with members)");
            return false;
        }
        out.node.se =
            Eigen::VectorXd::Zero(slope.slope.size());  // fixed DT: estimates without noise
        out.realizations = 0;  // nothing to test a pooled curvature against
    }
    out.node.tau = slope.t_mean;
    if (settings_.window_auto) out.noise = window_noise(rec.burst.t, rec.burst.members, t_window);
    if (budget_) out.sigma = TrajectoryBudget::standard_error(rec.burst, t_window);
    if (settings_.lift_apart) {
        // Each member's own slope over the window, less their mean (the ensemble's).
        out.member_deviation = std::move(fit.member_slopes);
        if (out.member_deviation.rows() > 0)
            out.member_deviation.rowwise() -= out.member_deviation.colwise().mean();
    }
    out.decay = estimate_decay_rate(rec.burst.t, rec.burst.x, t_window);
    if (settings_.adaptive && out.decay.ok && out.decay.rate < 0.0) {
        // A decay rate read from noise would halve DT for nothing (the slope's halves differ by
        // chance): only a change of slope beyond the members' spread counts.
        const DecayResolution res = decay_resolution(rec.burst.t, rec.burst.members, t_window);
        if (res.measured && !res.resolved) {
            out.decay.ok = false;
            out.decay.message = fmt::format(
                "the slope's change between the window's halves is within the realizations' "
                "noise (S = {:.3g} <= {:.3g}): the decay rate {:.3g} is not resolved",
                res.statistic, res.threshold, out.decay.rate);
        }
    }
    if (settings_.adaptive && std::isfinite(drift_rate())) {
        // No jump from a slope that is not the slow dynamics': a fast transient, or a wave
        // the realizations share that the window does not average out.
        const PhaseDrift d = phase_drift(rec.burst, t_window, drift_rate());
        const WaveCoherence w = wave_coherence(rec.burst, t_start);
        out.wave_period = w.period;  // NaN unless the ensemble mean oscillates twice
        if (d.drifting) {
            out.hold_kind = DtLimit::fast_transient;
            out.hold = "still in a fast transient (" + d.message + ")";
        } else if (w.in_phase &&
                   window() < 2.0 * w.period * (1.0 - 1e-9)) {  // in_phase: period measured
            out.hold_kind = DtLimit::in_phase_wave;
            out.hold = fmt::format(
                "{}: a least-squares slope over cpi.window = {:.3g} (< two periods) is biased "
                "by the common wave beyond its standard error; use cpi.window >= {:.3g}",
                w.message, window(), 2.0 * w.period);
        }
    }
    rec.window = slope.t_last - slope.t_first;
    return true;
}

void MultistepProjectiveIntegrator::accept_burst(const Measured& m, ControllerRecord& c) {
    history_.push_back(m.node);
    pool_.add(m.node);
    while (history_.size() > static_cast<std::size_t>(settings_.steps) + 1) {
        history_.pop_front();
        curvature_only_front_ = false;
    }
    t_end_ = m.t_end;
    x_end_ = m.x_end;
    decay_ = m.decay;
    hold_kind_ = m.hold_kind;
    hold_ = m.hold;
    member_deviation_ = m.member_deviation;
    realizations_ = m.realizations;
    // cpi.accuracy: the ensemble's noise from a burst whose members the lift did not gather
    // onto one ICDF (the first, before any lift; every one when the lift keeps them apart).
    if (budget_ && std::isfinite(m.sigma) && (!budget_->ready() || settings_.spread_survives_lift))
        budget_->measure(m.sigma);
    // The decay the burst resolved (measure_burst() cleared one within its noise) may earn the
    // accumulated error a contraction credit.
    if (budget_)
        budget_->credit(m.decay.ok && m.decay.rate < 0.0 ? -m.decay.rate
                                                         : std::numeric_limits<double>::quiet_NaN(),
                        1.0 / burst_length());
    judge_window(m, c);
}

void MultistepProjectiveIntegrator::set_jump_tolerance(const JumpBasis& basis,
                                                       ControllerRecord& c) {
    if (!budget_ || !budget_->ready()) return;
    // An open-ended run: the budget is planned over ten of the longest cycles ahead. The jumps
    // to come are those before cpi.jump_until where the run sets it: after it no jump adds error.
    const double horizon = std::min(
        std::isfinite(end_time()) ? end_time()
                                  : t_end_ + 10.0 * (settings_.control.dt_max + burst_length()),
        jump_end());
    double tol = 0.0;
    if (horizon > t_end_)
        tol = budget_->jump_tolerance(basis.model(t_end_, prior_curvature(basis)), horizon,
                                      burst_length(), settings_.control.dt_max, budget_walk());
    // Spent (or no noise at all): a tolerance no jump of cpi.dt_min meets, so bursts run
    // directly.
    const double floor = 1e-12 * std::max(budget_->budget(), 1e-300);
    controller_.set_tolerance(std::max(tol, floor));
    c.budget = budget_->budget();
    c.ensemble_standard_error = budget_->state().sigma;
    c.budget_spent = budget_->spent(t_end_);
    c.contraction_rate = budget_->rate();
}

double MultistepProjectiveIntegrator::budget_walk() const {
    // The last accepted burst's own slope (not a pool's: its se is the walk over one window).
    // Its window is the one that burst had: it ended at t_end_ and its slope sits at the
    // window's middle, tau, on the uniform sampling grid (with no healing the first sample is
    // one interval after the lift; with cpi.healing_auto window() may since have changed).
    if (history_.empty()) return 0.0;
    return walk_rate(history_.back(), 2.0 * (t_end_ - history_.back().tau), settings_.slope_fit);
}

std::vector<SlopeNode> MultistepProjectiveIntegrator::method_nodes() const {
    const std::size_t usable = history_.size() - (curvature_only_front_ ? 1 : 0);
    const std::size_t q = std::min<std::size_t>(static_cast<std::size_t>(settings_.steps), usable);
    return {history_.end() - static_cast<std::ptrdiff_t>(q), history_.end()};
}

double MultistepProjectiveIntegrator::prior_curvature(const JumpBasis& basis) const {
    const std::size_t q = method_nodes().size();
    if (history_.size() < q + 1) return std::numeric_limits<double>::quiet_NaN();
    const std::vector<SlopeNode> nodes(history_.end() - static_cast<std::ptrdiff_t>(q + 1),
                                       history_.end());
    return basis.correction.empty() ? slope_divided_difference(nodes).norm
                                    : curvature_left(nodes, basis.correction).norm;
}

double MultistepProjectiveIntegrator::burst_length_from(const CoarseStepper& stepper) const {
    return burst_length_to_end(stepper.time(), end_time(), burst_length());
}

MultistepProjectiveIntegrator::JumpBasis MultistepProjectiveIntegrator::jump_basis() const {
    JumpBasis b;
    // Until the pool holds a burst (a restart from a checkpoint written before pooling), the
    // last burst's slope.
    if (settings_.slope != SlopeSource::pooled || pool_.size() == 0) {
        b.nodes = method_nodes();
        if (settings_.pooled_curvature) add_curvature_correction(b);
        return b;
    }
    b.pooled = pool_.estimate(pool_.size());  // the last cpi.pool bursts (fewer at the start)
    b.nodes = {b.pooled.node};
    b.committed = b.pooled.committed;
    return b;
}

void MultistepProjectiveIntegrator::add_curvature_correction(JumpBasis& b) const {
    if (pool_.size() < MultistepSettings::curvature_min_bursts) {
        b.correction_note =
            fmt::format("no curvature added: {} burst(s) measured, a pooled curvature needs {}",
                        pool_.size(), MultistepSettings::curvature_min_bursts);
        return;
    }
    std::vector<SlopeNode> nodes;
    std::vector<double> commitments;
    for (const PooledBurst& p : pool_.bursts()) {
        nodes.push_back(p.node);
        commitments.push_back(p.commitment);
    }
    PooledCurvature curvature = pooled_curvature(nodes);
    // A curvature within its noise would add its noise and no expected gain: only one the
    // bursts resolve is added (as a posteriori curvature counts only when resolved).
    const MeanSignificance sig = significance(curvature.value, curvature.variance, realizations_);
    if (!sig.measured) {
        b.correction_note = fmt::format(
            "no curvature added: {} realization(s) in the last burst, too few to test it against "
            "their noise (0 after a restart from a checkpoint written before cpi.curvature, until "
            "the next burst)",
            realizations_);
        return;
    }
    if (!sig.resolved) {
        b.correction_note = fmt::format(
            "no curvature added: the curvature pooled over {} bursts is within its noise (S = "
            "{:.3g} <= {:.3g})",
            nodes.size(), sig.statistic, sig.threshold);
        return;
    }
    b.correction_note = fmt::format(
        "the jump adds the curvature pooled over {} bursts (S = {:.3g} > {:.3g}, RMS "
        "{:.3g} +- {:.3g})",
        nodes.size(), sig.statistic, sig.threshold, rms(curvature.value),
        std::sqrt(curvature.variance.mean()));
    curvature.committed = committed_covariance(curvature, commitments);
    b.correction = std::move(curvature);
}

double MultistepProjectiveIntegrator::pooled_noisy_curvature(const SlopeNode& after) const {
    // The pool's bursts end with the jump's own slope; with the burst after the jump a line
    // through at least three slopes (two are the jump's own divided difference).
    if (pool_.size() < 2) return std::numeric_limits<double>::quiet_NaN();
    std::vector<SlopeNode> nodes;
    for (const PooledBurst& p : pool_.bursts()) nodes.push_back(p.node);
    nodes.push_back(after);
    const PooledCurvature b = pooled_curvature(nodes);
    return debiased_rms(b.value, b.variance);  // as the divided difference's norm
}

void MultistepProjectiveIntegrator::record_statistical(ControllerRecord& c, const JumpBasis& basis,
                                                       double dt) const {
    // The curvature plays no part in the statistical error.
    c.statistical_nodes = statistical_error(basis.model(t_end_, ControllerRecord::nan), dt);
    c.statistical = rms(c.statistical_nodes);
    c.statistical_jump =
        rms(statistical_error(basis.nodes, projection_weights(basis.nodes, t_end_, dt)));
    c.slope_source = settings_.slope;
    c.pooled_bursts = basis.committed.size() ? static_cast<int>(basis.pooled.bursts()) : 1;
    if (settings_.steps == 1 && pool_.size() > 0) {
        c.statistical_burst = dt * rms(pool_.bursts().back().node.se);
        c.statistical_pool = dt * rms(pool_.estimate(pool_.size()).node.se);
    }
}

double MultistepProjectiveIntegrator::plan_dt(ProjectiveStepRecord& rec,
                                              const JumpBasis& basis) const {
    const DtPlan p = controller_.plan({.model = basis.model(t_end_, prior_curvature(basis)),
                                       .decay = decay_,
                                       .hold = hold_kind_,
                                       .hold_message = hold_,
                                       .end_time = end_time(),
                                       .jump_end = jump_end(),
                                       .lift_reserve = lift_reserve_});
    ControllerRecord& c = rec.controller;
    c.limited_by = p.limited_by;
    c.dt_tolerance = p.dt_tolerance;
    c.dt_tolerance_2r = p.dt_tolerance_2r;
    c.dt_tolerance_4r = p.dt_tolerance_4r;
    if (p.stability) rec.stability = *p.stability;
    if (!p.message.empty()) append_message(rec, p.message);
    return p.dt;
}

ProjectiveStepRecord MultistepProjectiveIntegrator::step(CoarseStepper& stepper) {
    ProjectiveStepRecord rec;
    rec.t_start = stepper.time();
    rec.healing = healing_;
    rec.burst_length = burst_length();
    ControllerRecord& c = rec.controller;
    c.active = true;
    c.adaptive = settings_.adaptive;
    // cpi.accuracy: no tolerance before the first burst has measured the ensemble's noise.
    c.tolerance = settings_.adaptive && (!budget_ || budget_->ready())
                      ? controller_.setup().control.tolerance
                      : ControllerRecord::nan;
    EFDEM_EXPECTS(!settings_.adaptive || stepper.can_keep_state());

    Measured m;
    if (history_.empty()) {  // the first slope: one burst, no jump
        if (!measure_burst(stepper, rec, m, burst_length_from(stepper))) return rec;
        // No lift before it: with healing >= window its start is a second window, whose slope
        // gives the first jump a curvature (for the error model only).
        const double w = settings_.burst.window;
        SlopeNode early;
        if (settings_.adaptive && settings_.burst.healing >= w * (1.0 - 1e-12) &&
            window_node(settings_.slope_fit, rec.burst, m.t_end - 2.0 * w, m.t_end - w, early)) {
            history_.push_back(std::move(early));
            curvature_only_front_ = true;
        }
        accept_burst(m, c);
        rec.status = StepStatus::burst_only;
        rec.t_end = t_end_;
        rec.x_end = rec.x_projected = x_end_;
        rec.slope = m.node.slope;
        rec.slope_standard_error = m.node.se;
        c.limited_by = DtLimit::first_burst;
        return rec;
    }

    // The jump starts from the end of the last accepted burst, with its slope(s).
    rec.t_end = t_end_;
    rec.x_end = x_end_;
    const JumpBasis basis = jump_basis();
    const std::vector<SlopeNode>& nodes = basis.nodes;
    rec.slope = nodes.back().slope;
    rec.slope_standard_error = nodes.back().se;
    c.steps = static_cast<int>(nodes.size());
    set_jump_tolerance(basis, c);
    if (settings_.adaptive) c.tolerance = controller_.setup().control.tolerance;
    const long attempt = totals_.attempts + totals_.direct + 1;
    const bool forced_shrink =
        settings_.force.kind == ForcedDecision::Kind::shrink && settings_.force.attempt == attempt;
    const bool forced_reject =
        settings_.force.kind == ForcedDecision::Kind::reject && settings_.force.attempt == attempt;

    rec.dt_requested = plan_dt(rec, basis);
    if (forced_shrink) {  // as if a jump of the planned DT had been rejected (tests)
        controller_.jump_failed(rec.dt_requested);
        rec.dt_requested = plan_dt(rec, basis);
        append_message(rec, "DT halved (forced)");
    }
    rec.dt = rec.dt_requested;
    if (rec.dt == 0.0) {  // one burst of direct simulation from where we are
        if (c.limited_by == DtLimit::below_dt_min) ++totals_.direct;
        if (!measure_burst(stepper, rec, m, burst_length_from(stepper))) return rec;
        accept_burst(m, c);
        rec.status = StepStatus::burst_only;
        rec.x_projected = rec.x_end;
        controller_.direct_burst_done();
        return rec;
    }
    ++totals_.attempts;

    const std::vector<double> w = projection_weights(nodes, t_end_, rec.dt);
    c.predicted_truncation =
        jump_error(basis.model(t_end_, prior_curvature(basis)), rec.dt).truncation;
    record_statistical(c, basis, rec.dt);
    // The method's truncation is D omega to leading order (multistep_projection.hpp): what a
    // pooled curvature adds, and what the burst after the jump judges.
    const double omega = omega_integral(nodes, t_end_, rec.dt);
    Eigen::VectorXd x = x_end_ + projected_increment(nodes, w);
    if (!basis.correction.empty()) {
        const Eigen::VectorXd added = omega * basis.correction.value;
        x += added;
        append_message(
            rec, fmt::format("{}: {:.3g} (RMS) added to X", basis.correction_note, rms(added)));
    } else if (!basis.correction_note.empty())
        append_message(rec, basis.correction_note);
    if (!repair_projection(rec, x, repair_)) {
        controller_.jump_failed(rec.dt);  // the next attempt jumps less far
        return rec;
    }
    if (settings_.adaptive) stepper.keep_state();
    if (settings_.lift_apart && stepper.lifts_apart() && member_deviation_.rows() > 0) {
        stepper.lift_apart(x, rec.dt * member_deviation_, t_end_ + rec.dt);
        c.member_step = rec.dt * rms(member_deviation_.reshaped());
    } else
        stepper.lift(x, t_end_ + rec.dt);
    rec.lifted = true;
    const double lift_error = std::isfinite(stepper.lift_error()) ? stepper.lift_error() : 0.0;
    if (settings_.count_lift_error) {
        c.lift = lift_error;
        lift_reserve_ = lift_error;  // what the next jump plans for
    }
    std::string why = stepper.lift_failure();
    if (why.empty() && settings_.adaptive && lift_error > c.tolerance)
        // The lift alone spent more than the jump may: whatever the burst after it measured,
        // the jump's error would exceed the tolerance (too few particles of a class where the
        // target puts them, docs/error_control.md "A lift that misses its target").
        why = fmt::format(
            "it left the ensemble mean {:.3g} d_p (RMS) from the projected X, more than the jump's "
            "tolerance {:.3g}",
            stepper.lift_error(), c.tolerance);
    if (!why.empty()) {
        // The micro model is not at X: as a rejected jump, without the burst that would judge it.
        EFDEM_EXPECTS(settings_.adaptive);  // cpi_settings refuses lifts that can fail otherwise
        stepper.return_to_kept_state();
        controller_.jump_failed(rec.dt);
        ++totals_.rejected;
        rec.lifted = false;
        rec.status = StepStatus::lift_failed;
        append_message(rec, "the lift failed (" + why +
                                "); back to the state before the jump, the next one shorter");
        return rec;
    }

    ProjectiveStepRecord after;  // the burst that judges the jump
    after.t_start = stepper.time();
    // A jump shortened after the end rule placed it (by the stability check) can
    // leave between one and two bursts: this burst then runs to the end of the run.
    const bool measured = measure_burst(stepper, after, m, burst_length_from(stepper));
    // Whatever the verdict on the jump, the burst says whether lifts leave a transient: the
    // healing of the bursts to come.
    judge_healing(after.burst, after.t_start, c);
    if (!measured) {
        if (settings_.adaptive) stepper.return_to_kept_state();
        rec.status = StepStatus::invalid_burst;
        rec.burst = std::move(after.burst);
        append_message(rec, "the burst after the jump: " + after.message +
                                (settings_.adaptive ? "; back to the state before the jump" : ""));
        controller_.jump_failed(rec.dt);
        return rec;
    }
    rec.burst = std::move(after.burst);
    rec.window = after.window;
    rec.t_start = after.t_start;

    std::vector<SlopeNode> judged = nodes;
    judged.push_back(m.node);
    const DividedDifference d = basis.correction.empty() ? slope_divided_difference(judged)
                                                         : curvature_left(judged, basis.correction);
    // A curvature within its own noise is no evidence of truncation error: its debiased norm is
    // still positive half the time by chance, and it would reject jumps the tolerance was spent
    // on with the statistical part (the prior curvature of such a plan is already 0).
    // A norm that debiases to 0 stays 0 in every mode (with `pooled` too: charging the pooled
    // line there as well overcharged a decaying toy 1.4x, its own norm being clipped at 0).
    double curvature = d.norm;
    if (settings_.adaptive &&
        settings_.noisy_curvature != MultistepSettings::NoisyCurvature::counted &&
        curvature > 0.0) {
        const int realizations =
            rec.burst.members.empty() ? 0 : static_cast<int>(rec.burst.members.front().rows());
        const MeanSignificance sig = significance(d.value, d.noise_variance, realizations);
        if (sig.measured && !sig.resolved) {
            const std::string within = fmt::format(
                "the curvature after the jump is within its noise (S = {:.3g} <= "
                "{:.3g}): truncation error judged ",
                sig.statistic, sig.threshold);
            const double pooled =
                settings_.noisy_curvature == MultistepSettings::NoisyCurvature::pooled
                    ? pooled_noisy_curvature(m.node)
                    : std::numeric_limits<double>::quiet_NaN();
            if (std::isfinite(pooled))
                append_message(
                    rec, fmt::format("{}{:.3g} from the curvature pooled over {} "
                                     "bursts, not {:.3g}",
                                     within, pooled * omega, pool_.size() + 1, curvature * omega));
            else
                append_message(rec, fmt::format("{}0, not {:.3g}", within, curvature * omega));
            curvature = std::isfinite(pooled) ? pooled : 0.0;
        }
    }
    c.truncation = curvature * omega;
    c.truncation_nodes = d.value.cwiseAbs() * omega;

    const JumpErrorModel posterior = basis.model(t_end_, curvature);
    const JumpVerdict verdict =
        controller_.judge(rec.dt, {c.statistical, c.truncation, c.lift}, posterior, forced_reject);
    if (verdict.accepted) {
        if (settings_.adaptive) stepper.confirm_kept_state();
        if (!verdict.message.empty()) append_message(rec, verdict.message);
        c.accepted = true;
        // The jump's slope noise is now in the state (before the new burst joins the pool).
        if (basis.committed.size()) {
            pool_.commit(basis.pooled, rec.dt);
        } else if (settings_.steps == 1 && pool_.size() > 0) {
            pool_.commit(pool_.estimate(1), rec.dt);
        }
        if (!basis.correction.empty())  // and omega c_k of every burst its curvature used
            pool_.add_commitments(basis.correction.weights, omega);
        if (budget_ && budget_->ready()) {
            // The lift's error is charged as a bias, like the truncation part: it need not
            // average out over the jumps (a relaxation that moves heights one way).
            c.budget_walk = std::sqrt(rec.dt * budget_walk());
            budget_->commit(t_end_ + rec.dt, c.statistical, c.truncation + c.lift,
                            c.budget_walk * c.budget_walk);
            c.budget_spent = budget_->spent(t_end_ + rec.dt);
        }
        accept_burst(m, c);
        ++totals_.accepted;
        totals_.dt_taken += rec.dt;
        if (settings_.adaptive) {
            totals_.dt_tolerance += c.dt_tolerance;
            totals_.dt_tolerance_2r += c.dt_tolerance_2r;
            totals_.dt_tolerance_4r += c.dt_tolerance_4r;
        }
        totals_.statistical += c.statistical;
        totals_.truncation += c.truncation;
        rec.status = StepStatus::projected;
        return rec;
    }
    // Rejected: back to the end of the last accepted burst; the controller caps the next step.
    stepper.return_to_kept_state();
    ++totals_.rejected;
    rec.status = StepStatus::rejected;
    append_message(rec, verdict.message);
    return rec;
}

std::string MultistepProjectiveIntegrator::summary(int realizations, long bursts) const {
    const Totals& t = totals_;
    // Every burst counts: the first one (which only measures a slope) and any the end of the
    // run left no room to jump from are bursts without a jump.
    const long without = std::max(0L, bursts - t.accepted - t.rejected - t.direct);
    std::string s = fmt::format(
        "{}: {} bursts: {} with a jump kept, {} with a jump rejected, {} run directly (tolerance "
        "allowed DT < cpi.dt_min), {} without a jump (the first, which measures the first slope; "
        "those in a fast transient; the end of the run{})",
        name(), bursts, t.accepted, t.rejected, t.direct, without,
        std::isfinite(jump_end())
            ? fmt::format("; those after cpi.jump_until (t = {:.6g})", jump_end())
            : std::string());
    // Every rejected jump cost a burst of DEM time that bought nothing.
    if (t.rejected > 0)
        s += fmt::format(
            "; {:.0f} % of the jumps tried were rejected",
            100.0 * static_cast<double>(t.rejected) / static_cast<double>(t.accepted + t.rejected));
    if (settings_.slope == SlopeSource::pooled)
        s += fmt::format("; slopes pooled over up to {} bursts", settings_.pool);
    if (settings_.healing_auto) s += fmt::format("; healing from evidence, now {:g}", healing_);
    if (settings_.window_auto)
        s += fmt::format("; window from evidence, now {:g} ({} over {} burst(s))", window_,
                         fast_time2_ > 0.0
                             ? fmt::format("fast noise about the slow path c = {:.3g}", fast_time2_)
                             : std::string("no fast noise about the slow path measured"),
                         noise_measurements_);
    if (budget_ && budget_->ready())
        s += fmt::format(
            "; trajectory budget {:.3g} d_p (cpi.accuracy {:g} x the ensemble's standard error "
            "{:.3g}), {:.3g} d_p spent",
            budget_->budget(), budget_->accuracy(), budget_->state().sigma, budget_->spent(t_end_));
    if (t.accepted == 0) return s;
    const double n = static_cast<double>(t.accepted);
    const double err = t.statistical + t.truncation;
    s += fmt::format(
        "\nmean DT kept {:.4g}; mean error per jump {:.3g} (statistical {:.3g}, truncation "
        "{:.3g}): "
        "the statistical part is {:.0f}% of the error budget",
        t.dt_taken / n, err / n, t.statistical / n, t.truncation / n,
        err > 0 ? 100.0 * t.statistical / err : 0.0);
    if (settings_.adaptive)
        s += fmt::format(
            "\nmean DT the tolerance allows: {:.4g} with R = {}, {:.4g} with R = {}, {:.4g} with R "
            "= {} "
            "(before the growth and dt_max limits)",
            t.dt_tolerance / n, realizations, t.dt_tolerance_2r / n, 2 * realizations,
            t.dt_tolerance_4r / n, 4 * realizations);
    return s;
}

IntegratorState MultistepProjectiveIntegrator::save_state() const {
    MultistepState s;
    s.t_end = t_end_;
    s.x_end = x_end_;
    s.history.assign(history_.begin(), history_.end());
    s.curvature_only_front = curvature_only_front_;
    s.decay = decay_;
    s.hold_kind = hold_kind_;
    s.hold = hold_;
    s.controller = controller_.state();
    s.totals = totals_;
    s.pool.assign(pool_.bursts().begin(), pool_.bursts().end());
    s.healing = healing_;
    s.lift_reserve = lift_reserve_;
    s.realizations = realizations_;
    s.member_deviation = member_deviation_;
    if (budget_) s.budget = budget_->state();
    if (settings_.window_auto) {
        s.window = window_;
        s.window_fast_time2 = fast_time2_;
        s.window_measurements = noise_measurements_;
    }
    return s;
}

void MultistepProjectiveIntegrator::restore_state(const IntegratorState& state) {
    history_.clear();
    curvature_only_front_ = false;
    pool_.restore({});
    healing_ = settings_.burst.healing;
    lift_reserve_ = 0.0;
    realizations_ = 0;
    window_ = settings_.burst.window;
    fast_time2_ = std::numeric_limits<double>::quiet_NaN();
    noise_measurements_ = 0;
    member_deviation_ = Eigen::MatrixXd();
    if (budget_) budget_->restore({});
    controller_.set_burst(burst_length(), window());
    if (!state) return;  // nothing saved: as new
    const MultistepState& s = *state;
    EFDEM_EXPECTS(s.history.size() <= static_cast<std::size_t>(settings_.steps) + 1);
    t_end_ = s.t_end;
    x_end_ = s.x_end;
    history_.assign(s.history.begin(), s.history.end());
    curvature_only_front_ = s.curvature_only_front;
    decay_ = s.decay;
    hold_kind_ = s.hold_kind;
    hold_ = s.hold;
    controller_.restore(s.controller);
    totals_ = s.totals;
    // Checkpoints of runs without cpi.lift = own (or before it): the members move alike until
    // the next accepted burst measures them.
    if (settings_.lift_apart) member_deviation_ = s.member_deviation;
    // Checkpoints of runs without cpi.accuracy: the budget starts with the next burst's noise.
    if (budget_ && !std::isnan(s.budget.sigma)) budget_->restore(s.budget);
    // A restart with a smaller cpi.pool keeps the newest bursts.
    const std::size_t skip =
        s.pool.size() > pool_.capacity() ? s.pool.size() - pool_.capacity() : 0;
    pool_.restore({s.pool.begin() + static_cast<std::ptrdiff_t>(skip), s.pool.end()});
    // Checkpoints before cpi.healing_auto have no healing: the configured one.
    healing_ = std::isnan(s.healing) ? settings_.burst.healing : s.healing;
    // Checkpoints before the lift reserve: none (the next lift measures it).
    lift_reserve_ = std::isnan(s.lift_reserve) ? 0.0 : s.lift_reserve;
    realizations_ = s.realizations;
    // Checkpoints of runs without cpi.window_auto (or before it) have no window: the configured.
    if (settings_.window_auto && !std::isnan(s.window)) {
        window_ = s.window;
        fast_time2_ = s.window_fast_time2;
        noise_measurements_ = s.window_measurements;
    }
    controller_.set_burst(burst_length(), window());
}

}  // namespace efdem::coarse
