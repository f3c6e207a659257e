#pragma once
/// \file
/// The table of coarse observables a scene can choose with `cpi.observable` (and that
/// `observe.compact` records next to a direct run): one row per observable, its name, a
/// factory from the p-grid and a one-line summary. To add an observable: derive from
/// EnsembleObservable (ensemble_observable.hpp), add ONE row to kObservables in
/// observable_table.cpp, list the .cpp in coarse/CMakeLists.txt (ARCHITECTURE.md).

#include "coarse/demixing/ensemble_observable.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "core/registry.hpp"

namespace efdem::coarse {

using ObservableTable = Registry<EnsembleObservable, const ProbabilityGrid&>;

/// The table of all coarse observables (one checked-in table; the first row is the default).
const ObservableTable& observable_table();

}  // namespace efdem::coarse
