#include "coarse/demixing/observable_table.hpp"

#include <memory>

#include "coarse/demixing/compact_observable.hpp"
#include "coarse/demixing/rank_observable.hpp"

namespace efdem::coarse {

namespace {
std::unique_ptr<EnsembleObservable> make_icdf(const ProbabilityGrid& grid) {
    return std::make_unique<IcdfObservable>(grid.size());
}
std::unique_ptr<EnsembleObservable> make_ranks(const ProbabilityGrid& grid) {
    return std::make_unique<RankObservable>(grid);
}
std::unique_ptr<EnsembleObservable> make_compact(const ProbabilityGrid& grid) {
    return std::make_unique<CompactObservable>(grid);
}

// THE table of coarse observables. One row each: name (as written in `cpi.observable = ...`),
// factory, one-line summary.
constexpr ObservableTable::Entry kObservables[] = {
    {"icdf", &make_icdf, "the ensemble-mean ICDF of the observed species on the p-grid (m nodes)"},
    {"compact", &make_compact,
     "(A, B, C, D) of y = Q_top - Q_L ~ max[A p + B + C e^(D p), 0] (paper Eq. 3), fitted per "
     "sample"},
    {"ranks", &make_ranks,
     "each light quantile's rank among all particles of its realization, as a height in the "
     "run's first ensemble-mean bed (m nodes): a shift or expansion of the whole bed cancels"},
};
constexpr ObservableTable kTable{kObservables};
}  // namespace

const ObservableTable& observable_table() {
    return kTable;
}

}  // namespace efdem::coarse
