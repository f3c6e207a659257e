#include "mpi_driver/run/run_advice.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "dem/gas/gas_drag.hpp"

namespace efdem::mpi_driver {

std::vector<std::string> run_advice(bool cpi, bool jumps_end, const dem::System& system) {
    std::vector<std::string> out;
    const auto* drag = dynamic_cast<const dem::GasDrag*>(system.find_effect("gas_drag"));
    if (!cpi || jumps_end || drag == nullptr) return out;
    const std::vector<std::string> packed = drag->species_not_fluidized();
    if (packed.empty() || packed.size() == system.species().size()) return out;
    // Measured on the demo bed at U_s = 0.19 (docs/accuracy_vs_cost.md, "Under CPI no
    // realization stops"): every direct realization came to rest after 277-925 time units, no
    // CPI realization in any run (68, up to 672 units of DEM time each), with any lift.
    out.push_back(fmt::format(
        "U_s = {:g} does not fluidize {} on its own (efdem --check): as the bed demixes it can "
        "defluidize and come to rest, and CPI's lifts keep beds moving (on the demo bed at "
        "U_s = 0.19 every direct realization came to rest within 1,000 time units, none under "
        "CPI). This cpi run follows the demixing while the beds move; for an end state in which "
        "they rest, end the jumps before the beds can stop (cpi.jump_until) and let the run go "
        "on directly (docs/accuracy_vs_cost.md, \"Jumps, then direct\")",
        drag->spec().superficial_velocity, fmt::join(packed, ", ")));
    return out;
}

}  // namespace efdem::mpi_driver
