#include "coarse/equation_free/projective/projective_run.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "coarse/equation_free/estimators/phase_drift.hpp"
#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "core/contracts.hpp"
#include "core/log.hpp"

namespace efdem::coarse {

ProjectiveRun::ProjectiveRun(const CpiSettings& settings, CoarseStepper& stepper,
                             CoarseVariable primary, std::optional<CoarseVariable> fallback)
    : settings_(settings),
      stepper_(stepper),
      primary_(std::move(primary)),
      fallback_(std::move(fallback)) {
    EFDEM_EXPECTS(settings_.burst() > 0.0);
}

bool ProjectiveRun::steady_by_drift(const ProjectiveStepRecord& rec) {
    if (stepper_.any_at_rest()) {
        drift_.clear();  // a partly stopped ensemble: its spread would hide the others' drift
        return false;
    }
    const bool accepted_burst =
        rec.status == StepStatus::projected || rec.status == StepStatus::burst_only;
    if (accepted_burst && rec.slope_standard_error.size() == rec.slope.size())
        drift_.add({rec.t_end - 0.5 * rec.window, rec.slope, rec.slope_standard_error});
    return drift_.steady();
}

void ProjectiveRun::use(const CoarseVariable& variable) {
    if (variable.select) variable.select();
    integrator_ = settings_.make_integrator(variable.repair);
    integrator_->set_end_time(t_end_);
    integrator_->set_jump_end(state_.t_origin + settings_.jump_until);
}

double ProjectiveRun::planned_micro_time(double dt) const {
    return coarse::planned_micro_time(stepper_.time(), t_end_, settings_.burst(), dt);
}

ProjectiveRunOutcome ProjectiveRun::run(double duration,
                                        const std::optional<ProjectiveRunState>& resume) {
    if (resume) {
        state_ = *resume;
    } else {
        state_ = ProjectiveRunState{};
        state_.t_origin = stepper_.time();
    }
    t_end_ = state_.t_origin + duration;
    const double tol = time_tolerance(t_end_);
    const double burst = settings_.burst();
    // From here on the fallback is the coarse variable when the primary one failed, now or
    // before the checkpoint this run resumed from.
    use(state_.fell_back && fallback_ ? *fallback_ : primary_);
    if (resume) integrator_->restore_state(state_.integrator);
    drift_.restore(state_.drift);
    ProjectiveRunOutcome out;
    out.end_status = "completed";
    if ((settings_.warmup > 0 || settings_.warmup_until_steady) && !state_.warmed_up) {
        // The initial state (a packed bed at rest) is far from the slow manifold: run it
        // directly until the fast transients are gone before the first projection.
        state_.integrator = integrator_->save_state();
        for (auto* o : observers_) o->between_steps(*this);
        warm_up();
        for (auto* o : observers_) o->warmup_done(*this);
    }
    state_.warmed_up = true;
    while (stepper_.time() < t_end_ - tol) {
        state_.integrator = integrator_->save_state();
        state_.drift = drift_.save();
        for (auto* o : observers_) o->between_steps(*this);
        // The integrators shorten their jumps to end at t_end (the adaptive one also runs a burst
        // that would leave less than one more on to t_end, burst_length_to_end); only a run
        // shorter than warm-up plus one burst (or one whose period bursts were extended) can be
        // left with less.
        if (t_end_ - stepper_.time() < burst - tol) {
            log::info(
                "stopping at t = {:.6g}: the {:.4g} time units left are less than one "
                "burst ({:.4g})",
                stepper_.time(), t_end_ - stepper_.time(), burst);
            break;
        }
        const ProjectiveStepRecord rec = integrator_->step(stepper_);
        ++state_.coarse_steps;
        if (rec.status == StepStatus::projected && rec.dt > 0) ++out.jumps;
        for (auto* o : observers_) o->step_done(*this, rec);
        // cpi.finish: the end status names the end state's time and why it is one.
        const auto end_at = [&](double t, const std::string& why) {
            out.end_state_time = t;
            const std::string what =
                fmt::format("end state at t = {:.6g}, {:.6g} time units after the start: {}", t,
                            t - state_.t_origin, why);
            out.end_status = "completed (" + what + ")";
            log::info("cpi.finish = steady: {}", what);
        };
        if (settings_.finish_at_end_state && !std::isnan(stepper_.end_state_since())) {
            // Nothing changes from here on however long the run: the end state is reached.
            end_at(stepper_.end_state_since(), "every realization at rest");
            break;
        }
        if (settings_.finish_on_drift && steady_by_drift(rec)) {
            end_at(drift_.since(),
                   fmt::format("statistically steady, the slope pooled over the last {} bursts "
                               "within its noise at {} checks in a row (z = {:.2f} <= {:.3g})",
                               kDriftBursts, kDriftConfirmations, drift_.z(), DriftTest::kSteadyZ));
            break;
        }
        if (rec.advanced()) {
            state_.without_progress = 0;
            continue;
        }
        if (fallback_ && !state_.fell_back && rec.status == StepStatus::invalid_burst) {
            // The primary variable could not be formed (e.g. the compact fit failed): continue
            // with the fallback, which is always defined.
            std::string why = primary_.failure ? primary_.failure() : std::string{};
            if (why.empty()) why = "its restriction failed";
            log::warn(
                "the {} observable failed at t = {:.6g}: {} ({}); continuing with the {} as the "
                "coarse variable",
                primary_.description, stepper_.time(), why, rec.message, fallback_->description);
            state_.fell_back = true;
            use(*fallback_);
            continue;
        }
        if (rec.status == StepStatus::stopped_unstable ||
            ++state_.without_progress >= kMaxStepsWithoutProgress) {
            out.end_status = fmt::format("stopped at t = {:.6g}: {} ({})", stepper_.time(),
                                         to_string(rec.status), rec.message);
            log::warn("cpi run {}", out.end_status);
            break;
        }
    }
    out.coarse_steps = state_.coarse_steps;
    out.simulated_time = stepper_.time() - state_.t_origin;
    out.fell_back = state_.fell_back;
    if (out.fell_back && out.end_status == "completed")
        out.end_status = fmt::format("completed ({} observable fell back to {})", primary_.name,
                                     fallback_ ? fallback_->name : std::string{"?"});
    const bool saw_every_step = !resume || resume->coarse_steps == 0;
    if (out.jumps == 0 && saw_every_step && out.end_status.rfind("completed", 0) == 0) {
        const std::string why =
            out.coarse_steps == 0
                ? fmt::format(
                      "the {:.4g} time units after the warm-up were less than one burst ({:.4g})",
                      t_end_ - stepper_.time(), burst)
                : fmt::format("{} coarse step(s), each a burst only", out.coarse_steps);
        out.end_status +=
            fmt::format(" (no projective jump: {}; all {:.4g} time units were direct simulation)",
                        why, out.simulated_time);
        log::warn(
            "cpi run made no projective jump: {}; all {:.4g} time units were direct simulation. A "
            "cpi run "
            "gains only when run.duration leaves room for jumps after cpi.warmup (and a steady "
            "warm-up) "
            "and the controller takes them (each coarse step's status and message say why it did "
            "not jump)",
            why, out.simulated_time);
    }
    return out;
}

void ProjectiveRun::warm_up() {
    // The warm-up starts the run: t_origin (also in a run resumed inside it).
    const double t0 = state_.t_origin, burst = settings_.burst();
    const double tol = time_tolerance(t_end_);
    // Room for one burst after the warm-up.
    const double room = std::max(0.0, t_end_ - burst - t0);
    BurstSamples w;
    if (!settings_.warmup_until_steady) {
        // In pieces of one burst length (whole samples: a burst is), each followed by a safe
        // point; a resumed run runs only what is left. The same samples as one piece.
        const double total = std::min(settings_.warmup, t_end_ - state_.t_origin);
        while (state_.warmup_done < total - tol) {
            const double piece = std::min(burst, total - state_.warmup_done);
            w = {};
            stepper_.run(piece, w);
            state_.warmup_done += piece;
            if (state_.warmup_done < total - tol)
                for (auto* o : observers_) o->between_steps(*this);
        }
        log::info("warm-up: {:.4g} time units of direct simulation before the first coarse step",
                  settings_.warmup);
        return;
    }
    // Until steady: `length` first, in pieces of one burst; then one window at a time while
    // the phase signal's drift over the last burst length is beyond its noise and faster than
    // warmup_drift_rate = steady_drift_rate(cpi.tolerance, burst) (adaptive; a derivation, see
    // cpi_settings.hpp), i.e. cpi.tolerance per burst. A safe point before every piece but the
    // first keeps the samples the next drift test reads (ProjectiveRunState::warmup_tail).
    const double length = std::min(std::max(settings_.warmup, burst), room);
    w = std::move(state_.warmup_tail);  // a resumed run: the samples it had
    state_.warmup_tail = {};
    // Resumed at a safe point of the drift loop: it is the one before the next window.
    bool at_safe_point = state_.warmup_done > 0 && state_.warmup_done >= length - tol;
    while (state_.warmup_done < length - tol) {
        const double piece = std::min(burst, length - state_.warmup_done);
        stepper_.run(piece, w);
        state_.warmup_done += piece;
        if (state_.warmup_done < length - tol) warmup_safe_point(w, burst);
    }
    const double window = settings_.window();
    const double t_limit = std::min(t0 + settings_.warmup + settings_.warmup_max, t0 + room);
    while (true) {
        const PhaseDrift d =
            phase_drift(w, stepper_.time() - burst - tol, settings_.warmup_drift_rate);
        if (!d.measured) {
            log::warn(
                "warm-up: {:.4g} time units; the drift of the phase signal cannot be measured (no "
                "per-realization phase signals, or fewer than 2 realizations): warm-up by time "
                "only",
                stepper_.time() - t0);
            return;
        }
        if (!d.drifting) {
            log::info(
                "warm-up: {:.4g} time units of direct simulation before the first coarse step, "
                "until "
                "steady: {}",
                stepper_.time() - t0, d.message);
            return;
        }
        if (stepper_.time() + window > t_limit + tol) {
            log::warn(
                "warm-up: stopped after {:.4g} time units (cpi.warmup + cpi.warmup_max, or the end "
                "of the "
                "run) while still in a fast transient: {}",
                stepper_.time() - t0, d.message);
            return;
        }
        if (!at_safe_point) warmup_safe_point(w, burst);
        at_safe_point = false;
        stepper_.run(window, w);
        state_.warmup_done += window;
    }
}

void ProjectiveRun::warmup_safe_point(const BurstSamples& w, double burst) {
    // The samples of the last burst length (and a tolerance), as the drift test selects them.
    const std::size_t first =
        first_sample_at_or_after(w.t, stepper_.time() - burst - time_tolerance(t_end_));
    BurstSamples& tail = state_.warmup_tail;
    tail = {};
    const auto keep = [first](const auto& all, auto& kept) {
        if (!all.empty()) kept.assign(all.begin() + static_cast<std::ptrdiff_t>(first), all.end());
    };
    keep(w.t, tail.t);
    keep(w.member_phase, tail.member_phase);
    keep(w.member_expansion, tail.member_expansion);
    for (auto* o : observers_) o->between_steps(*this);
    tail = {};
}

double planned_micro_time(double t_now, double t_end, double burst, double dt) {
    EFDEM_EXPECTS(burst > 0.0);
    const double tol = time_tolerance(t_end);
    double micro = 0.0;
    for (double t = t_now; t_end - t >= burst - tol;) {
        t += burst;
        micro += burst;
        t += std::min(dt, end_of_run_jump_limit(t, t_end, dt, burst));
    }
    return micro;
}

}  // namespace efdem::coarse
