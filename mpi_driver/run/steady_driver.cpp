#include "mpi_driver/run/steady_driver.hpp"

#include <limits>
#include <string>

#include <fmt/format.h>

#include "coarse/demixing/icdf_gap_coordinates.hpp"
#include "coarse/equation_free/steady/steady_run.hpp"
#include "core/log.hpp"
#include "mpi_driver/parallel/stop_signal.hpp"
#include "mpi_driver/run/driver.hpp"

namespace efdem::mpi_driver {

namespace {
/// What the observers saw, kept for the end of a run cut short (signal, failure).
struct SolveTrace {
    long solve = 0;                    ///< the current solve
    long last_iteration = -1;          ///< its last iterate seen
    coarse::SteadySolveRecord latest;  ///< the current solve's record so far
    coarse::Branch branch;             ///< continuation: the points so far
};
}  // namespace

SteadySolveResult solve_steady(
    EnsembleStepper& stepper, const RunSettings& s, RunRecorder* recorder, Progress& progress,
    double hand_off_time, const std::function<void(coarse::SteadyRunOutcome&)>& end_state_time) {
    const coarse::SteadyRunSettings& ss = s.steady;
    coarse::EnsembleObservable& observable = stepper.observable();
    coarse::SteadyRun run(
        ss, stepper, observable.repair_hook([&stepper] { return stepper.height_range(); }),
        [&stepper](double value) { stepper.set_parameter(value); },
        ss.gap_coordinates ? coarse::icdf_gap_coordinates() : coarse::CoarseCoordinates{});
    const double micro_start = stepper.micro_time();
    // mode = steady | continuation: run.duration is the solve's budget (0: none); a hand-off's
    // run.duration was the cpi run's span, and its solve ends by steady.max_iterations.
    const double budget = s.is_steady() ? s.duration : 0.0;
    double parameter = ss.continuation ? ss.parameter_start : 0.0;
    SolveTrace trace;

    run.set_iterate_observer([&](const coarse::SteadySolveRecord& rec) -> std::string {
        const long iteration = static_cast<long>(rec.residuals.size()) - 1;
        if (iteration <= trace.last_iteration) ++trace.solve;  // a new solve began
        trace.last_iteration = iteration;
        trace.latest = rec;
        SteadyIterateRecord it;
        it.solve = trace.solve;
        it.iteration = iteration;
        it.residual = rec.state_residuals.back();  // in heights, whatever the solver's coordinates
        it.noise = rec.state_noise.back();
        const Eigen::Index n = stepper.observable().dimension();
        it.x = rec.x.head(std::min<Eigen::Index>(n, rec.x.size()));
        it.parameter =
            ss.continuation && rec.x.size() > n ? rec.x[n] * ss.parameter_scale : parameter;
        it.dem_time = stepper.micro_time() - micro_start - ss.warmup;
        if (recorder) recorder->steady_iterate(it);
        const double wall = progress.elapsed_seconds();
        const double rate = wall > 0 ? stepper.particle_steps() / wall : 0.0;
        log::info(
            "steady: solve {} iterate {}: |F| = {:.4e} (noise {:.3e}, {:.2f} x noise){}; DEM time "
            "{:.4g}{} in "
            "{} wall ({:.3g} particle-steps/s)",
            it.solve, it.iteration, it.residual, it.noise,
            it.noise > 0 ? it.residual / it.noise : 0.0,
            ss.continuation ? fmt::format(" at {} = {:.5g}", ss.parameter, it.parameter)
                            : std::string{},
            it.dem_time, budget > 0 ? fmt::format(" of {:.4g}", budget) : std::string{},
            format_duration(wall), rate);
        if (stepper.interrupted())
            return fmt::format("stopped by {}", signal_name(stepper.interrupted()));
        if (budget > 0 && it.dem_time >= budget)
            return fmt::format("the DEM-time budget run.duration = {:g} is spent ({:.4g} used)",
                               budget, it.dem_time);
        return {};
    });
    run.set_point_observer([&](const coarse::Branch& b) {
        trace.branch = b;
        parameter = b.points.back().parameter;
        if (recorder) recorder->branch_point(b.points.back());
    });

    const auto interrupted_status = [&stepper] {
        return fmt::format(
            "interrupted: {} at t = {:.6g}; no checkpoint (a steady solve cannot be "
            "continued; its best iterate is saved)",
            signal_name(stepper.interrupted()), stepper.time());
    };
    SteadySolveResult result;
    coarse::SteadyRunOutcome& out = result.outcome;
    try {
        out = run.run();
    } catch (const RunInterrupted&) {
        // Between two samples of an evaluation: what was found so far is what is saved.
        out = run.header();
        out.solve = trace.latest;
        out.solve.reason = coarse::SteadyStopReason::stopped;
        out.solve.message = fmt::format("stopped by {}", signal_name(stepper.interrupted()));
        out.branch = trace.branch;
        out.branch.end_reason = out.solve.message;
        out.end_status = interrupted_status();
        result.stop_signal = stepper.interrupted();
    }
    if (stepper.interrupted() && result.stop_signal == 0) {
        // The observer stopped the solve at an iterate.
        result.stop_signal = stepper.interrupted();
        out.end_status = interrupted_status();
    }
    out.hand_off_time = hand_off_time;
    if (end_state_time) end_state_time(out);
    if (recorder) recorder->steady_outcome(out);
    return result;
}

RunSummary run_steady(EnsembleStepper& stepper, const RunSettings& s, RunRecorder* recorder,
                      Progress& progress) {
    const double micro_start = stepper.micro_time();
    const SteadySolveResult result =
        solve_steady(stepper, s, recorder, progress, std::numeric_limits<double>::quiet_NaN());
    const coarse::SteadyRunOutcome& out = result.outcome;
    RunSummary sum;
    sum.stop_signal = result.stop_signal;
    sum.solve_interrupted = result.stop_signal != 0;
    stepper.finish(sum.stop_signal ? kExitInterrupted : 0);
    sum.end_status = out.end_status;
    sum.unconverged = sum.stop_signal == 0 && !out.converged;
    sum.simulated_time = stepper.micro_time() - micro_start;
    fill_totals(sum, stepper, progress);
    sum.lift_seconds = stepper.overhead().lift_seconds;
    if (sum.unconverged) report_unconverged(out);
    return sum;
}

void report_unconverged(const coarse::SteadyRunOutcome& out) {
    const coarse::SteadySolveRecord& r = out.solve;
    // In heights [d_p] like the run file's /steady/iterate/residual (the solver's own |F| is
    // in its coordinates, log gaps with steady.coordinates = gaps).
    std::string history;
    for (std::size_t k = 0; k < r.state_residuals.size(); ++k)
        history += fmt::format("{}{:.3e}", k ? ", " : "", r.state_residuals[k]);
    log::error("{}", out.end_status);
    if (!out.continuation)
        log::error(
            "residual history |F| [d_p]: {} (noise {:.3e}); the best iterate (|F| = {:.4e}) is "
            "/steady/best in "
            "the run file. What to try: a longer steady.tau (slow modes then contract more per "
            "evaluation), more realizations (the noise falls as 1/sqrt(R)){}",
            history, r.state_noise.empty() ? 0.0 : r.state_noise.back(), r.best_state_residual(),
            out.solver == "newton"
                ? ", a larger steady.difference_step when GMRES did not converge, steady.solver = "
                  "anderson for a stable state"
                : ", more steady.max_iterations while |F| still falls, steady.solver = newton for "
                  "an unstable or nearly neutral state");
    else
        log::error(
            "no branch point converged; the first point's residual history |F| [d_p]: {}. What "
            "to try: a "
            "longer steady.tau, more realizations, a larger steady.difference_step",
            history);
}

}  // namespace efdem::mpi_driver
