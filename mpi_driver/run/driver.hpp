#pragma once
/// \file
/// The two run modes, executed by the root (the other ranks serve the EnsembleStepper):
///
/// * direct: every realization runs the DEM for run.duration; samples are recorded as they come;
/// * cpi: the coarse run loop coarse::ProjectiveRun (warm-up, bursts, jumps, lifts, end-of-run
///   rule, stop conditions, observable fallback) on the EnsembleStepper, with the observers that
///   record each step, print progress and write checkpoints plugged in.
///
/// Both end with EnsembleStepper::finish() so that the other ranks leave serve(). Both write a
/// checkpoint every RunControl::checkpoint_interval coarse steps / samples (a whole-ensemble
/// file, checkpoint_writer.hpp) and continue a restarted run from RunControl::resume, so that
/// the output equals that of the uninterrupted run.

#include <optional>

#include "coarse/demixing/ensemble_observable.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"
#include "mpi_driver/output/progress.hpp"
#include "mpi_driver/output/run_recorder.hpp"
#include "mpi_driver/run/run_settings.hpp"

namespace efdem::mpi_driver {

/// Checkpointing and restart of a run loop.
struct RunControl {
    /// Checkpoint every this many coarse steps (cpi) or samples (direct); 0: never. Needs the
    /// stepper's checkpoint writer.
    long checkpoint_interval = 0;
    /// The loop state saved in the checkpoint a restarted run continues from.
    std::optional<DriverState> resume;
};

/// The totals every run mode reports: DEM time, run-loop wall time, particle-steps, restriction
/// time.
void fill_totals(RunSummary& sum, const EnsembleStepper& stepper, const Progress& progress);

RunSummary run_direct(EnsembleStepper& stepper, const RunSettings& settings, Progress& progress,
                      const RunControl& control = {});

/// The stepper restricts to its observable (the coarse variable); `fallback`: the observable the
/// run switches to when that one fails (null: none, e.g. when it is the ICDF already).
RunSummary run_cpi(EnsembleStepper& stepper, const RunSettings& settings,
                   coarse::EnsembleObservable* fallback, RunRecorder* recorder, Progress& progress,
                   const RunControl& control = {});

}  // namespace efdem::mpi_driver
