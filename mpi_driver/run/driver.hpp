#pragma once
/// \file
/// The two run loops, executed by the root (the other ranks serve the EnsembleStepper):
///
/// * direct: every realization runs the DEM for run.duration; samples are recorded as they come;
/// * cpi: repeat { burst -> slope -> projective forward Euler jump -> lift } until run.duration
///   is reached (DT fixed, or DT = k T with travelling waves).
///
/// Both end with EnsembleStepper::finish() so that the other ranks leave serve(). Both write a
/// checkpoint every RunControl::checkpoint_interval coarse steps / samples (a whole-ensemble
/// file, checkpoint_writer.hpp) and continue a restarted run from RunControl::resume, so that
/// the output equals that of the uninterrupted run.

#include <optional>

#include "coarse/demixing/ensemble_observable.hpp"
#include "mpi_driver/checkpoint/checkpoint_format.hpp"
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

RunSummary run_direct(EnsembleStepper& stepper, const RunSettings& settings, Progress& progress,
                      const RunControl& control = {});

/// DEM time a CPI run still needs from t_now to t_end with bursts of `burst` (> 0) and jumps
/// of `dt`, shortened at the end as the integrators do (coarse::end_of_run_jump_limit):
/// the work the progress line's estimate of the time left is based on.
double planned_dem_time(double t_now, double t_end, double burst, double dt);

/// `fallback`: the ICDF observable the run switches to when the compact observable fails
/// (y(p) identically zero, or a fit that does not converge); ignored with cpi.observable = icdf.
RunSummary run_cpi(EnsembleStepper& stepper, const RunSettings& settings,
                   coarse::EnsembleObservable& fallback, RunRecorder* recorder, Progress& progress,
                   const RunControl& control = {});

}  // namespace efdem::mpi_driver
