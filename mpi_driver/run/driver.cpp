#include "mpi_driver/run/driver.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "coarse/equation_free/projective_run.hpp"
#include "core/log.hpp"
#include "mpi_driver/run/checkpoint_observer.hpp"
#include "mpi_driver/run/progress_observer.hpp"
#include "mpi_driver/run/step_report_observer.hpp"

namespace efdem::mpi_driver {

namespace {
/// The coarse variable `observable`, as the run loop sees it: selecting it switches the
/// stepper's restriction; ICDF targets are repaired into the heights the particles occupy.
coarse::CoarseVariable coarse_variable(coarse::EnsembleObservable& observable, EnsembleStepper& stepper) {
    coarse::CoarseVariable v;
    v.name = std::string(observable.name());
    v.description = std::string(observable.label());
    v.repair = observable.repair_hook([&stepper] { return stepper.height_range(); });
    v.select = [&stepper, &observable] { stepper.set_observable(observable); };
    v.failure = [&observable] { return observable.failure_reason(); };
    return v;
}

void fill_totals(RunSummary& sum, const EnsembleStepper& stepper, const Progress& progress) {
    sum.dem_time = stepper.micro_time();
    sum.wall_seconds = progress.elapsed_seconds();
    sum.particle_steps = stepper.particle_steps();
    sum.restrict_seconds = stepper.overhead().restrict_seconds;
}
}  // namespace

RunSummary run_direct(EnsembleStepper& stepper, const RunSettings& s, Progress& progress, const RunControl& control) {
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
    while (done < total) {
        long n = std::min(chunk, total - done);
        if (every > 0) n = std::min(n, every - done % every);
        scratch = {};
        stepper.run(static_cast<double>(n) * s.observe.interval, scratch);
        done += n;
        if (every > 0 && done % every == 0 && done < total) {
            const auto path = stepper.checkpoint(done, state);
            log::info("checkpoint {} (t = {:.6g})", path.string(), stepper.time());
        }
    }
    stepper.finish();
    progress.update(stepper.time(), stepper.particle_steps(), "done", true);
    RunSummary sum;
    sum.simulated_time = s.duration;
    fill_totals(sum, stepper, progress);
    sum.end_status = std::abs(stepper.time() - t_end) < 1e-6 * std::max(1.0, t_end) ? "completed" : "incomplete";
    return sum;
}

RunSummary run_cpi(EnsembleStepper& stepper, const RunSettings& s, coarse::EnsembleObservable* fallback,
                   RunRecorder* recorder, Progress& progress, const RunControl& control) {
    if (s.cpi.projection == coarse::CoarseRunSettings::Projection::periods && stepper.realizations() > 1)
        log::warn("cpi.projection = periods measures the wave period from the ensemble-mean centre of "
                  "mass; the {} realizations' waves start in phase (they fluidize together) but lose phase "
                  "over some 60-80 time units on the demo bed, and then the period of the mean cannot be "
                  "measured (docs/accuracy_vs_cost.md). DT = k T is the single-realization method of the "
                  "paper (Fig. 2b); for an ensemble use cpi.projection = adaptive with cpi.window of two "
                  "periods", stepper.realizations());
    coarse::EnsembleObservable& primary = stepper.observable();
    std::optional<coarse::CoarseVariable> fallback_variable;
    if (fallback) fallback_variable = coarse_variable(*fallback, stepper);
    coarse::ProjectiveRun run(s.cpi, stepper, coarse_variable(primary, stepper), std::move(fallback_variable));

    StepReportObserver report(stepper, recorder);
    ProgressObserver progress_line(stepper, progress);
    std::optional<CheckpointObserver> checkpoints;
    if (control.checkpoint_interval > 0)
        checkpoints.emplace(stepper, control.checkpoint_interval, control.resume ? control.resume->coarse_steps : 0);
    if (checkpoints) run.add_observer(*checkpoints);
    run.add_observer(report);
    run.add_observer(progress_line);

    const coarse::ProjectiveRunOutcome out = run.run(s.duration, control.resume);
    stepper.finish();
    RunSummary sum;
    sum.end_status = out.end_status;
    sum.coarse_steps = out.coarse_steps;
    sum.simulated_time = out.simulated_time;
    fill_totals(sum, stepper, progress);
    sum.lift_seconds = stepper.overhead().lift_seconds;
    sum.controller = run.integrator().summary(stepper.realizations());
    if (!sum.controller.empty()) log::info("{}", sum.controller);
    return sum;
}

}  // namespace efdem::mpi_driver
