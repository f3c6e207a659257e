#include "mpi_driver/run/run_provenance.hpp"

#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "coarse/demixing/probability_grid.hpp"
#include "dem/beds/bed_diagnostics.hpp"
#include "dem/gas/gas_drag.hpp"

namespace efdem::mpi_driver {

std::optional<dem::BedObservationSettings> bed_settings(const RunSettings& s,
                                                        const dem::System& any) {
    if (!s.observe.bed) return std::nullopt;
    dem::BedObservationSettings b;
    b.profile_dz = s.observe.profile_dz;
    b.profile_slabs =
        s.observe.profile_height > 0
            ? static_cast<std::size_t>(std::ceil(s.observe.profile_height / b.profile_dz - 1e-9))
            : dem::default_profile_slabs(any, b.profile_dz);
    b.mixing_layer = s.observe.mixing_layer;
    b.mixing_species = s.observe.species;
    b.species = any.species().size();
    return b;
}

RunProvenance provenance(const MpiSession& mpi, const ParamTable& table, const RunSettings& s,
                         const dem::System& any,
                         const std::optional<dem::BedObservationSettings>& bed) {
    RunProvenance p;
    p.scene_file = table.file();
    p.scene_text = table.text();
    p.overrides = fmt::format("{}", fmt::join(table.overrides(), " "));
    for (const auto& r : table.resolved())
        p.parameters += fmt::format("{} = {}   [{}]\n", r.key, r.value, r.origin);
    p.mode = s.mode_name();
    p.hand_off = s.is_cpi() && s.hand_off;
    p.ranks = mpi.size();
    p.realizations_per_rank = s.realizations_per_rank;
    p.realizations = mpi.size() * s.realizations_per_rank;
    p.seed = s.seed;
    p.p_grid = coarse::ProbabilityGrid(s.observe.quantiles).values();
    p.observed_species = any.species()[s.observe.species].name;
    // The SI scales, where the scene gives them (gas_drag's physical keys, not gas_drag.A).
    if (const auto* drag = dynamic_cast<const dem::GasDrag*>(any.find_effect("gas_drag"));
        drag && drag->spec().physical) {
        const dem::GasProperties& g = drag->spec().gas;
        p.si = SiUnits::from(g.particle_diameter, g.particle_density, g.gravity);
    }
    if (bed) {
        for (std::size_t k = 0; k < bed->species; ++k)
            p.species_names.push_back(any.species()[static_cast<dem::SpeciesId>(k)].name);
        p.profile_dz = bed->profile_dz;
        p.profile_slabs = static_cast<long>(bed->profile_slabs);
        p.mixing_layer = bed->mixing_layer;
        p.weight_per_area = dem::weight_per_area(any);
    }
    return p;
}

}  // namespace efdem::mpi_driver
