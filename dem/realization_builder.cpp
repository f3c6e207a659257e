#include "dem/realization_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numeric>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "core/log.hpp"
#include "core/rng.hpp"
#include "dem/io/lammps_data.hpp"
#include "dem/settling/settling.hpp"

namespace efdem::dem {

namespace {
/// Realization `spec.realization`'s bed from bed.read: the file, checked against the scene (the
/// reader checks the box, the species' names, diameters and densities; here the counts per
/// species against bed.count).
Particles read_settled_bed(const BedSpec& bed, const DemScene& scene, const Params& bed_scope,
                           const RealizationSpec& spec) {
    check_kept_bed_exists(bed, bed_scope, spec.realization);
    const std::filesystem::path file = bed.read_file(spec.realization);
    Particles p = read_lammps_data(file, scene.species, scene.domain);
    std::vector<long> count(scene.species.size(), 0);
    for (const SpeciesId s : p.species()) ++count[s];
    if (count != bed.count) {
        std::string have, want;
        for (std::size_t s = 0; s < count.size(); ++s) {
            const std::string& name = scene.species[static_cast<SpeciesId>(s)].name;
            have += fmt::format("{}{} {}", s ? ", " : "", count[s], name);
            want += fmt::format("{}{}", s ? " " : "", bed.count[s]);
        }
        bed_scope.fail("read",
                       fmt::format("{} holds {}, but bed.count = {}", file.string(), have, want),
                       "a bed written by a run with the same bed.count, species and box");
    }
    return p;
}

/// Reorders `p` by tag.
void in_tag_order(Particles& p) {
    std::vector<Index> order(p.size());
    std::iota(order.begin(), order.end(), Index{0});
    std::sort(order.begin(), order.end(),
              [&](Index a, Index b) { return p.tag()[a] < p.tag()[b]; });
    p.permute(order);
}

/// bed.read.velocity_rms: Gaussian velocities of that rms speed added, from the realization's
/// own stream, so that realizations sharing one bed part at once.
void add_velocities(Particles& p, const BedSpec& bed, const RealizationSpec& spec) {
    if (bed.read_velocity_rms <= 0) return;
    RandomStream rng(spec.seed, static_cast<std::uint64_t>(spec.realization), "bed_velocities");
    const double sigma = bed.read_velocity_rms / std::sqrt(3.0);
    for (Vec3& v : p.v()) {
        const double vx = rng.normal(), vy = rng.normal(), vz = rng.normal();
        v += Vec3{sigma * vx, sigma * vy, sigma * vz};
    }
}
}  // namespace

void check_kept_bed_exists(const BedSpec& bed, const Params& bed_scope, long realization) {
    if (bed.read.empty()) return;
    const std::filesystem::path file = bed.read_file(realization);
    std::error_code ec;
    if (std::filesystem::is_regular_file(file, ec)) return;
    bed_scope.fail("read",
                   bed.read_shared ? fmt::format("names no file ({} does not exist)", file.string())
                                   : fmt::format("has no bed for realization {}: {} does not exist",
                                                 realization, file.string()),
                   bed.read_shared
                       ? "a bed file an earlier run wrote with bed.write (one per realization: "
                         "NAME_r0000.data, ...)"
                       : "the name an earlier run of as many realizations or more gave "
                         "bed.write (it wrote NAME_r0000.data, ...), or bed.read.shared = true "
                         "to give every realization one file");
}

Particles build_bed(const BedSpec& bed, const DemScene& scene, const Params& root,
                    const RealizationSpec& spec, const SettlingReport& settling, Particles* built) {
    Particles p;
    if (bed.source == BedSpec::Source::lattice && !bed.read.empty() && !spec.restart) {
        p = read_settled_bed(bed, scene, root.scope("bed"), spec);
        if (built) *built = p;  // the file's bed, without the velocities added next
        add_velocities(p, bed, spec);
        if (spec.realization == 0)
            log::info("bed: starting from the settled bed{} {} (bed.read; not settled){}",
                      bed.read_shared ? " every realization shares," : " of realization 0,",
                      bed.read_file(0).string(),
                      bed.read_shared ? "; the realizations' ICDFs stay correlated for a mixing "
                                        "time (docs/how_to_choose.md, \"Reuse a settled bed\")"
                                      : "");
    } else if (bed.source == BedSpec::Source::lattice) {
        p = lattice_bed(bed, scene, spec);
        if (bed.settle && !spec.skip_settling) {
            p = settle_bed(std::move(p), bed, scene, root, spec, settling);
            // Settling leaves the particles in its neighbour list's order; back in tag order, the
            // order a bed file is read in, so that a run from the kept bed (bed.read) hands the
            // System the same arrays, and its first cell sort gives the same order.
            in_tag_order(p);
        }
        if (built) *built = p;
    } else {
        p = read_lammps_data(bed.file, scene.species, scene.domain);
        if (built) *built = p;
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
    const char* key = bed.source == BedSpec::Source::lammps_data ? "file"
                      : bed.read.empty()                         ? "source"
                                                                 : "read";
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

System build_system(const Params& root, const RealizationSpec& spec, const SettlingReport& settling,
                    Particles* built) {
    DemScene scene = DemScene::from_params(root);
    auto effects = make_effects(scene, root);
    const std::string warning = check_time_step(scene, root, effects);
    if (!warning.empty() && spec.realization == 0) log::warn("{}", warning);
    const BedSpec bed = BedSpec::from_params(root.scope("bed"), scene);
    Particles particles = build_bed(bed, scene, root, spec, settling, built);
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
