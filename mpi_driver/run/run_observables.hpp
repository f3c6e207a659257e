#pragma once
/// \file
/// RunObservables: the coarse observables a run uses, made from coarse::observable_table()
/// according to the settings: the one every sample is restricted to, the fallback a cpi run
/// switches to when it fails, and one recorded only for comparison (observe.compact).

#include <memory>

#include "coarse/demixing/ensemble_observable.hpp"
#include "mpi_driver/run/run_settings.hpp"

namespace efdem::mpi_driver {

struct RunObservables {
    /// The restriction of every sample: cpi.observable in a cpi run, the ICDF in a direct run.
    std::unique_ptr<coarse::EnsembleObservable> primary;
    /// cpi: the ICDF (always defined) when primary is another observable; otherwise null.
    std::unique_ptr<coarse::EnsembleObservable> fallback;
    /// observe.compact: the compact (A,B,C,D), recorded at every sample, when primary is not
    /// already compact; otherwise null.
    std::unique_ptr<coarse::EnsembleObservable> recorded;

    static RunObservables from_settings(const RunSettings& settings);
};

}  // namespace efdem::mpi_driver
