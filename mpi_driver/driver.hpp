#pragma once
/// \file
/// The two run loops, executed by the root (the other ranks serve the EnsembleStepper):
///
/// * direct: every realization runs the DEM for run.duration; samples are recorded as they come;
/// * cpi: repeat { burst -> slope -> projective forward Euler jump -> lift } until run.duration
///   is reached (DT fixed, or DT = k T with travelling waves).
///
/// Both end with EnsembleStepper::finish() so that the other ranks leave serve().

#include "coarse/ensemble_observable.hpp"
#include "mpi_driver/ensemble_stepper.hpp"
#include "mpi_driver/progress.hpp"
#include "mpi_driver/run_recorder.hpp"
#include "mpi_driver/run_settings.hpp"

namespace efdem::mpi_driver {

RunSummary run_direct(EnsembleStepper& stepper, const RunSettings& settings, Progress& progress);

/// `fallback`: the ICDF observable the run switches to when the compact observable fails
/// (y(p) identically zero, or a fit that does not converge); ignored with cpi.observable = icdf.
RunSummary run_cpi(EnsembleStepper& stepper, const RunSettings& settings,
                   coarse::EnsembleObservable& fallback, RunRecorder* recorder, Progress& progress);

}  // namespace efdem::mpi_driver
