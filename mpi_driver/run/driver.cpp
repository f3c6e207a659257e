#include "mpi_driver/run/driver.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include <fmt/format.h>
#include "coarse/equation_free/estimators/arrival_time.hpp"
#include "coarse/equation_free/projective/projective_run.hpp"
#include "core/error.hpp"
#include "core/log.hpp"

#include "mpi_driver/parallel/stop_signal.hpp"
#include "mpi_driver/run/checkpoint_observer.hpp"
#include "mpi_driver/run/kept_bursts_observer.hpp"
#include "mpi_driver/run/progress_observer.hpp"
#include "mpi_driver/run/steady_driver.hpp"
#include "mpi_driver/run/step_report_observer.hpp"
#include "mpi_driver/run/stop_observer.hpp"

namespace efdem::mpi_driver {

namespace {
/// The coarse variable `observable`, as the run loop sees it: selecting it switches the
/// stepper's restriction; ICDF targets are repaired into the heights the particles occupy.
coarse::CoarseVariable coarse_variable(coarse::EnsembleObservable& observable,
                                       EnsembleStepper& stepper) {
    coarse::CoarseVariable v;
    v.name = std::string(observable.name());
    v.description = std::string(observable.label());
    v.repair = observable.repair_hook([&stepper] { return stepper.height_range(); });
    v.select = [&stepper, &observable, repair = v.repair] {
        stepper.set_observable(observable);
        stepper.set_member_repair(repair);  // cpi.lift = members: each realization's own target too
    };
    v.failure = [&observable] { return observable.failure_reason(); };
    return v;
}

/// The end of a run stopped by a signal: the checkpoint written where it can be continued.
void stopped(RunSummary& sum, const EnsembleStepper& stepper,
             const std::filesystem::path& checkpoint, double checkpoint_time) {
    sum.stop_signal = stepper.interrupted();
    sum.checkpoint = checkpoint.string();
    sum.checkpoint_time = checkpoint_time;
    sum.end_status =
        checkpoint.empty()
            ? fmt::format("interrupted: {} at t = {:.6g}; no checkpoint (this efdem has no HDF5)",
                          signal_name(sum.stop_signal), stepper.time())
            : fmt::format("interrupted: {} at t = {:.6g}; checkpoint {} (t = {:.6g})",
                          signal_name(sum.stop_signal), stepper.time(), sum.checkpoint,
                          checkpoint_time);
}
/// Within this of the solve's answer a kept burst's end state counts as at the end state: the
/// solve's own stopping threshold on |F| (steady.noise_factor x the noise), times sqrt(2) because
/// both the burst's state and the answer carry that noise.
double arrival_radius(const RunSettings& s, double noise) {
    return std::sqrt(2.0) * s.steady.newton.stop.noise_factor * noise;
}

/// cpi.hand_off = steady: the cpi run's state at its end goes to the steady solver; the run's
/// end status and exit code then include the solve's (exit 3 when it does not converge). A
/// signal ends the stepper here (exit 4; the solve is not checkpointed).
void hand_off(EnsembleStepper& stepper, const RunSettings& s, RunRecorder* recorder,
              Progress& progress, const KeptBurstsObserver& kept, RunSummary& sum) {
    const double t_end = stepper.time();
    const double cpi_dem_time = stepper.micro_time();
    if (stepper.any_at_rest())
        log::warn(
            "cpi.hand_off: a realization is at rest at t = {:.6g}; the steady solve lifts it too, "
            "but a bed the gas no longer moves keeps any lifted state (Phi_tau(X) = X for it), "
            "so its part of F is not a test of steadiness",
            t_end);
    log::info(
        "cpi.hand_off: the cpi run ended at t = {:.6g} ({}) after {:.4g} of DEM time; its state "
        "goes to the steady solver ({})",
        t_end, sum.end_status, cpi_dem_time,
        s.steady.solver == coarse::SteadyRunSettings::Solver::anderson ? "anderson" : "newton");
    stepper.begin_steady_solve();
    // The time to the end state is known once the solve has found it: it is measured from the
    // kept bursts, and recorded with the outcome (the recorder takes it from there).
    std::function<void(coarse::SteadyRunOutcome&)> arrival = [&kept,
                                                              &s](coarse::SteadyRunOutcome& o) {
        if (!o.converged || o.solve.state_noise.empty()) return;
        o.end_state_time = coarse::arrival_time(kept.times(), kept.states(), o.solve.x,
                                                arrival_radius(s, o.solve.state_noise.back()));
        o.end_state_time_is_bound = kept.only_a_bound(o.end_state_time);
    };
    const SteadySolveResult solved = solve_steady(stepper, s, recorder, progress, t_end, arrival);
    const coarse::SteadyRunOutcome& out = solved.outcome;
    // The run's status leads with what a reader must know first: "completed" only when both
    // parts did ("interrupted: ..." and "not converged: ..." otherwise, as in mode = steady).
    sum.end_status =
        out.converged && solved.stop_signal == 0
            ? fmt::format("{}; then the steady solve: {}", sum.end_status, out.end_status)
            : fmt::format(
                  "{} (the steady solve of cpi.hand_off; the cpi run before "
                  "it: {})",
                  out.end_status, sum.end_status);
    if (solved.stop_signal != 0) {
        stepper.finish(kExitInterrupted);
        sum.stop_signal = solved.stop_signal;
        sum.solve_interrupted = true;
        return;
    }
    sum.unconverged = !out.converged;
    if (sum.unconverged) {
        report_unconverged(out);
        return;
    }
    const coarse::SteadySolveRecord& r = out.solve;
    const double residual = r.state_residuals.empty() ? 0.0 : r.state_residuals.back();
    const double noise = r.state_noise.empty() ? 0.0 : r.state_noise.back();
    std::string band;
    if (!out.spectrum.leading.empty()) {
        // |x - x*| <= (|F| + |SE|) / (1 - |mu_1|) along the slowest mode (docs/steady_states.md).
        const double mu = std::abs(out.spectrum.leading.front().mu);
        band = mu < 1.0 ? fmt::format(
                              "; the end state is within (|F| + noise) / (1 - |mu_1|) = "
                              "{:.3g} of the steady state (|mu_1| = {:.3g})",
                              (residual + noise) / (1.0 - mu), mu)
                        : fmt::format("; |mu_1| = {:.3g} >= 1: no band (not a stable state)", mu);
    }
    const double radius = arrival_radius(s, noise);
    const std::string reached =
        std::isfinite(out.end_state_time)
            ? fmt::format(
                  "reached {}t = {:.6g} (from the cpi run's kept burst ending then, every "
                  "one lies within {:.3g} of it: sqrt(2) x steady.noise_factor x the noise)",
                  out.end_state_time_is_bound ? "at or before (this process resumed a checkpoint "
                                                "and saw no burst outside it) "
                                              : "at ",
                  out.end_state_time, radius)
            : fmt::format(
                  "not reached by the cpi run's bursts (its last kept burst is farther "
                  "than {:.3g} from it: sqrt(2) x steady.noise_factor x the noise); the "
                  "solve took it from t = {:.6g}",
                  radius, t_end);
    log::info(
        "cpi.hand_off: end state {}; the solve refined it in {} evaluations of Phi_{:g} ({:.4g} of "
        "DEM time; {:.4g} in all): |F| = {:.4g}, noise {:.4g}, mean light height {:.4g} d_p{}",
        reached, out.evaluations, out.tau, out.micro_time, stepper.micro_time(), residual, noise,
        coarse::mean_height(r.x), band);
}
}  // namespace

void fill_totals(RunSummary& sum, const EnsembleStepper& stepper, const Progress& progress) {
    sum.dem_time = stepper.micro_time();
    // A restarted run's wall time counts the processes before it too (as its DEM time and
    // particle-steps do); where theirs is unknown, this process's alone.
    const double before = stepper.wall_before();
    sum.resumed_wall_seconds = before;
    sum.wall_seconds = progress.elapsed_seconds() + (std::isfinite(before) ? before : 0.0);
    sum.particle_steps = stepper.particle_steps();
    sum.restrict_seconds = stepper.overhead().restrict_seconds;
}

RunSummary run_direct(EnsembleStepper& stepper, const RunSettings& s, Progress& progress,
                      const RunControl& control) {
    DriverState state;
    state.t_origin = stepper.time();
    if (control.resume) state = *control.resume;
    const double t_end = state.t_origin + s.duration;
    const long total = std::lround(s.duration / s.observe.interval);
    long done = stepper.samples_taken();
    const long every = control.checkpoint_interval;
    // Chunks of about 10 time units keep the burst buffer small; sampling is unaffected.
    const long chunk = std::max(1L, std::lround(10.0 / s.observe.interval));
    coarse::BurstSamples scratch;
    try {
        while (done < total) {
            long n = std::min(chunk, total - done);
            if (every > 0) n = std::min(n, every - done % every);
            scratch = {};
            stepper.run(static_cast<double>(n) * s.observe.interval, scratch);
            done += n;
            if (stepper.interrupted()) break;
            if (every > 0 && done % every == 0 && done < total) {
                const auto path = stepper.checkpoint(done, state);
                progress.note_checkpoint(
                    fmt::format("checkpoint {})", describe_checkpoint(path, stepper)));
            }
        }
    } catch (const RunInterrupted&) {
        // Cut short at a sample: every sample so far is recorded, a safe point.
    }
    RunSummary sum;
    if (stepper.interrupted() && stepper.samples_taken() < total) {
        // Every whole sample is a safe point in a direct run: checkpoint exactly here.
        std::filesystem::path path;
        if (stepper.can_checkpoint()) path = stepper.checkpoint(stepper.samples_taken(), state);
        stepper.finish(kExitInterrupted);
        sum.simulated_time = stepper.time() - state.t_origin;
        fill_totals(sum, stepper, progress);
        stopped(sum, stepper, path, stepper.time());
        return sum;
    }
    stepper.finish();
    progress.update(stepper.time(), stepper.particle_steps(), "done", true);
    sum.simulated_time = s.duration;
    fill_totals(sum, stepper, progress);
    sum.end_status =
        std::abs(stepper.time() - t_end) < 1e-6 * std::max(1.0, t_end) ? "completed" : "incomplete";
    if (stepper.failures() > 0)
        sum.end_status += fmt::format(" with {} failure(s)", stepper.failures());
    return sum;
}

RunSummary run_cpi(EnsembleStepper& stepper, const RunSettings& s,
                   coarse::EnsembleObservable* fallback, RunRecorder* recorder, Progress& progress,
                   const RunControl& control) {
    if (s.cpi.projection == coarse::CpiSettings::Projection::periods && stepper.realizations() > 1)
        log::warn(
            "cpi.projection = periods measures the wave period from the ensemble-mean centre of "
            "mass; the {} realizations' waves start in phase (they fluidize together) but lose "
            "phase "
            "over some 60-80 time units on the demo bed, and then the period of the mean cannot be "
            "measured (docs/accuracy_vs_cost.md). DT = k T is the single-realization method of the "
            "paper (Fig. 2b); for an ensemble use cpi.projection = adaptive with cpi.window of two "
            "periods",
            stepper.realizations());
    coarse::EnsembleObservable& primary = stepper.observable();
    std::optional<coarse::CoarseVariable> fallback_variable;
    if (fallback) fallback_variable = coarse_variable(*fallback, stepper);
    coarse::ProjectiveRun run(s.cpi, stepper, coarse_variable(primary, stepper),
                              std::move(fallback_variable));

    StopObserver stop(stepper);
    run.add_observer(stop);  // first: the resume point is kept before a checkpoint is written
    StepReportObserver report(stepper, recorder);
    ProgressObserver progress_line(stepper, progress);
    std::optional<CheckpointObserver> checkpoints;
    if (control.checkpoint_interval > 0)
        checkpoints.emplace(stepper, progress, control.checkpoint_interval,
                            control.resume ? control.resume->coarse_steps : 0);
    if (checkpoints) run.add_observer(*checkpoints);
    run.add_observer(report);
    run.add_observer(progress_line);
    KeptBurstsObserver kept(control.resume.has_value());  // cpi.hand_off: the time to the end state
    if (s.hand_off) run.add_observer(kept);

    coarse::ProjectiveRunOutcome out;
    try {
        std::optional<coarse::ProjectiveRunState> from = control.resume;
        while (true) {
            try {
                out = run.run(s.duration, from);
                break;
            } catch (const EnsembleChanged&) {
                // A realization failed (ensemble.on_failure = drop | replace): redo the coarse
                // step from where it began, with the changed ensemble.
                stepper.rebuild_after_failure();
                from = stepper.resume_driver();
                log::warn("continuing from t = {:.6g} with {} realizations ({} failure(s) so far)",
                          stepper.time(), stepper.active_realizations(), stepper.failures());
            }
        }
    } catch (const RunInterrupted&) {
        // Checkpointed where the interrupted coarse step began (or before the warm-up): the
        // restarted run redoes that step as the uninterrupted run did.
        std::filesystem::path path;
        if (stepper.can_checkpoint()) path = stepper.checkpoint_resume_point();
        stepper.finish(kExitInterrupted);
        RunSummary sum;
        sum.coarse_steps = run.state().coarse_steps;
        sum.simulated_time = stepper.time() - run.state().t_origin;
        fill_totals(sum, stepper, progress);
        stopped(sum, stepper, path, stepper.resume_point_time());
        return sum;
    }
    RunSummary sum;
    sum.end_status = out.end_status;
    sum.coarse_steps = out.coarse_steps;
    sum.simulated_time = out.simulated_time;
    if (stepper.failures() > 0 && sum.end_status.rfind("completed", 0) == 0)
        sum.end_status += fmt::format(" with {} failure(s)", stepper.failures());
    sum.controller = run.integrator().summary(stepper.realizations(), out.coarse_steps);
    if (!sum.controller.empty()) log::info("{}", sum.controller);
    if (s.hand_off) hand_off(stepper, s, recorder, progress, kept, sum);
    if (sum.stop_signal == 0) stepper.finish();
    fill_totals(sum, stepper, progress);
    sum.lift_seconds = stepper.overhead().lift_seconds;
    return sum;
}

}  // namespace efdem::mpi_driver
