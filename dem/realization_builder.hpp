#pragma once
/// \file
/// Building one DEM realization from a scene: the effects (dem/scene.hpp), the initial bed
/// (dem/beds/bed_builder.hpp, settled by dem/settling/settling.hpp) and the System that runs
/// them. The one file of dem/ that puts beds and settling together.
///
/// Keys read here besides those of DemScene and BedSpec (scope `watchdog`): `check_every`
/// (steps between health checks, default 1000, 0 = never) and `max_overlap` (largest overlap,
/// as a fraction of the pair's diameter, before a run is stopped, default 0.1).

#include "core/param_table.hpp"
#include "dem/beds/bed_builder.hpp"
#include "dem/beds/settling_report.hpp"
#include "dem/particles.hpp"
#include "dem/scene.hpp"
#include "dem/system.hpp"

namespace efdem::dem {

/// The initial particles of one realization according to `bed`: the lattice, settled unless
/// bed.settle = false or spec.skip_settling; or the settled bed bed.read names (its counts
/// checked against bed.count; a restart builds the unsettled lattice, which its checkpoint
/// overwrites, instead), with
/// bed.read.velocity_rms added; or the LAMMPS data file; then the species permutation when
/// bed.permute_species is set. `settling`: told how the settling goes (if it runs). `built`:
/// if given, receives the bed before what follows the settling (velocities added to a read
/// bed, the permutation): what `bed.write` keeps, so that a run from it (bed.read, the same
/// seed) starts exactly as this one.
Particles build_bed(const BedSpec& bed, const DemScene& scene, const Params& root,
                    const RealizationSpec& spec, const SettlingReport& settling = {},
                    Particles* built = nullptr);

/// InputError naming bed.read if the kept bed realization `realization` reads (bed.read) does
/// not exist; nothing without bed.read. (`efdem --check` builds realization 0 only and asks this
/// for the others.)
void check_kept_bed_exists(const BedSpec& bed, const Params& bed_scope, long realization);

/// Builds one realization: effects, initial bed (build_bed), System. InputError for bad input;
/// the same keys are read for every realization. `settling`, `built`: as in build_bed.
System build_system(const Params& root, const RealizationSpec& spec,
                    const SettlingReport& settling = {}, Particles* built = nullptr);

}  // namespace efdem::dem
