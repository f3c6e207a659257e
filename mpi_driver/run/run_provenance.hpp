#pragma once
/// \file
/// What a run records about itself before its first sample: the provenance of the run file
/// (scene, overrides, resolved parameters, layout, seed, p-grid, species) and how every
/// realization measures the bed when observe.bed is on.

#include <optional>

#include "core/param_table.hpp"
#include "dem/beds/bed_observation.hpp"
#include "dem/system.hpp"
#include "mpi_driver/output/run_recorder.hpp"
#include "mpi_driver/parallel/mpi_session.hpp"
#include "mpi_driver/run/run_settings.hpp"

namespace efdem::mpi_driver {

/// observe.bed: how every realization measures the bed (the same on every rank: the profile's
/// default top depends only on the particle count and sizes, which every realization shares);
/// none when the run does not record it.
std::optional<dem::BedObservationSettings> bed_settings(const RunSettings& s,
                                                        const dem::System& any);

/// `bed`: the run's bed_settings (the axes of /bed), if it records them.
RunProvenance provenance(const MpiSession& mpi, const ParamTable& table, const RunSettings& s,
                         const dem::System& any,
                         const std::optional<dem::BedObservationSettings>& bed);

}  // namespace efdem::mpi_driver
