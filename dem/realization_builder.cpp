#include "dem/realization_builder.hpp"

#include <cstdint>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "core/log.hpp"
#include "core/rng.hpp"
#include "dem/io/lammps_data.hpp"
#include "dem/settling/settling.hpp"

namespace efdem::dem {

Particles build_bed(const BedSpec& bed, const DemScene& scene, const Params& root,
                    const RealizationSpec& spec, const SettlingReport& settling) {
    Particles p;
    if (bed.source == BedSpec::Source::lattice) {
        p = lattice_bed(bed, scene, spec);
        if (bed.settle && !spec.skip_settling)
            p = settle_bed(std::move(p), bed, scene, root, spec, settling);
    } else {
        p = read_lammps_data(bed.file, scene.species, scene.domain);
    }
    if (bed.permute_species) {
        // A separate stream, so that permuting never shifts the lattice's packing draws.
        RandomStream rng(spec.seed, static_cast<std::uint64_t>(spec.realization),
                         "species_permutation");
        permute_species(p, scene.species, rng);
    }
    return p;
}

namespace {
/// Refuses an initial bed that the first health check of the run would stop (System::run checks
/// every SystemOptions::health_check_every steps): better at set-up, where nothing is lost, than
/// after the first thousand steps. Lattice beds cannot overlap (bed.jitter is bounded); a LAMMPS
/// data file can.
void check_initial_state(const System& sys, const BedSpec& bed, const Params& bed_scope,
                         const SystemOptions& options) {
    const char* key = bed.source == BedSpec::Source::lammps_data ? "file" : "source";
    const ThermoStats s = sys.thermo_stats();
    if (s.max_overlap > options.max_overlap_fraction)
        bed_scope.fail(
            key,
            fmt::format("starts with an overlap of {:.3g} diameters, beyond the limit of {:g} at "
                        "which the health check stops a run",
                        s.max_overlap, options.max_overlap_fraction),
            fmt::format("initial overlaps up to {:g} of the pair's diameter (or of the diameter, "
                        "at a wall): a looser packing",
                        options.max_overlap_fraction));
    if (const auto problem = sys.health_problem())
        bed_scope.fail(key, "gives an initial state the run would stop at: " + *problem);
}
}  // namespace

System build_system(const Params& root, const RealizationSpec& spec,
                    const SettlingReport& settling) {
    DemScene scene = DemScene::from_params(root);
    auto effects = make_effects(scene, root);
    const std::string warning = check_time_step(scene, root, effects);
    if (!warning.empty() && spec.realization == 0) log::warn("{}", warning);
    const BedSpec bed = BedSpec::from_params(root.scope("bed"), scene);
    Particles particles = build_bed(bed, scene, root, spec, settling);
    SystemOptions options;
    options.dt = scene.dt;
    options.skin = scene.skin;
    options.realization = spec.realization;
    // The numerical watchdog (System::health_problem): how often, and the largest overlap.
    const Params watchdog = root.scope("watchdog");
    options.health_check_every =
        watchdog.get_or<long>("check_every", 1000, Bounds::closed(0, 1000000000));
    // The watchdog catches blow-ups (overlaps of several % of d_p). Below 1e-4 d_p it would stop
    // sound runs: at kn = 2e5 the bottom contacts of a 15-layer bed at rest overlap by ~4e-5 d_p
    // and collisions in a fluidized bed by ~1e-3 (tests/physics/test_collisions.cpp).
    options.max_overlap_fraction =
        watchdog.get_or<double>("max_overlap", 0.1, Bounds::closed(1e-4, 1.0));
    System sys(scene.species, scene.domain, std::move(particles), std::move(effects), options);
    check_initial_state(sys, bed, root.scope("bed"), options);
    return sys;
}

}  // namespace efdem::dem
