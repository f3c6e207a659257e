#include "mpi_driver/run/run_observables.hpp"

#include <string_view>

#include "coarse/demixing/observable_table.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "core/contracts.hpp"

namespace efdem::mpi_driver {

namespace {
std::unique_ptr<coarse::EnsembleObservable> make(std::string_view name,
                                                 const coarse::ProbabilityGrid& grid) {
    const auto* entry = coarse::observable_table().find(name);
    EFDEM_EXPECTS(entry != nullptr);  // names come from the table (RunSettings checked them)
    return entry->make(grid);
}
}  // namespace

RunObservables RunObservables::from_settings(const RunSettings& s) {
    const coarse::ProbabilityGrid grid(s.observe.quantiles);
    RunObservables o;
    o.primary = make(s.lifts() ? std::string_view(s.observable) : std::string_view("icdf"), grid);
    if (s.is_cpi() && o.primary->name() != "icdf") o.fallback = make("icdf", grid);
    if (s.observe.compact && o.primary->name() != "compact") o.recorded = make("compact", grid);
    return o;
}

}  // namespace efdem::mpi_driver
