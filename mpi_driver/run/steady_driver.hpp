#pragma once
/// \file
/// mode = steady and mode = continuation on the EnsembleStepper (docs/steady_states.md): the
/// coarse loop coarse::SteadyRun with the run's observers plugged in. Executed by the root (the
/// other ranks serve the stepper); ends with EnsembleStepper::finish().
///
/// * every iterate is recorded as it comes (/steady/iterate) and logged with the DEM time it
///   has cost; every branch point likewise (/branch);
/// * run.duration > 0 is a budget of DEM time after the warm-up: the solve stops there, with
///   its best iterate saved;
/// * a solve that does not reach its stopping rule ends "not converged: ..." with what to try,
///   the best iterate in the run file, and RunSummary::unconverged (exit code 3);
/// * a stop signal ends the run at the next sample with the iterates so far recorded (no
///   checkpoint: a solve holds kept micro states that a checkpoint does not).
///
/// A cpi run with cpi.hand_off = steady calls solve_steady() where its own loop ended.

#include <functional>

#include "coarse/demixing/ensemble_observable.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"
#include "mpi_driver/output/progress.hpp"
#include "mpi_driver/output/run_recorder.hpp"
#include "mpi_driver/run/run_settings.hpp"

namespace efdem::mpi_driver {

RunSummary run_steady(EnsembleStepper& stepper, const RunSettings& settings, RunRecorder* recorder,
                      Progress& progress);

/// What solve_steady() found, and the signal that cut it short (0: none).
struct SteadySolveResult {
    coarse::SteadyRunOutcome outcome;
    int stop_signal = 0;
};

/// The steady solve itself (settings.steady) from the stepper's current state, with the
/// observers above (record, log, budget, signal): run_steady() and the hand-off of a cpi run
/// (cpi.hand_off = steady) use it. The stepper is not finished. `hand_off_time`: the coarse time
/// at which a cpi run handed its state over (NaN: mode = steady | continuation).
/// `end_state_time` (hand-off; may be empty): fills the outcome's time to the end state from its
/// answer, before it is recorded.
SteadySolveResult solve_steady(
    EnsembleStepper& stepper, const RunSettings& settings, RunRecorder* recorder,
    Progress& progress, double hand_off_time,
    const std::function<void(coarse::SteadyRunOutcome&)>& end_state_time = {});

/// The error lines of a solve that did not reach its stopping rule: the residual history, where
/// the best iterate is, and what to try.
void report_unconverged(const coarse::SteadyRunOutcome& outcome);

}  // namespace efdem::mpi_driver
