#include "dem/beds/bed_builder.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "core/rng.hpp"
#include "dem/io/lammps_data.hpp"

namespace efdem::dem {

namespace {
/// Sites per row and layer spacings of the lattice that holds the bed.
struct LatticeGeometry {
    long n, nx, ny;
    double ax, ay, az, z0;
};
LatticeGeometry lattice_geometry(const BedSpec& bed, const DemScene& scene) {
    LatticeGeometry g{};
    g.n = std::accumulate(bed.count.begin(), bed.count.end(), 0L);
    g.nx = std::max(1L, static_cast<long>(std::floor(scene.domain.lx / bed.spacing)));
    g.ny = std::max(1L, static_cast<long>(std::floor(scene.domain.ly / bed.spacing)));
    g.ax = scene.domain.lx / static_cast<double>(g.nx);
    g.ay = scene.domain.ly / static_cast<double>(g.ny);
    g.az = std::max(g.ax, g.ay);
    g.z0 = 0.5 * g.az;
    return g;
}
/// Height of the top of the highest lattice sphere (with jitter).
double lattice_top(const BedSpec& bed, const DemScene& scene) {
    const LatticeGeometry g = lattice_geometry(bed, scene);
    const long layers = (g.n + g.nx * g.ny - 1) / (g.nx * g.ny);
    return g.z0 + static_cast<double>(layers - 1) * g.az + bed.jitter +
           0.5 * scene.species.max_diameter();
}
}  // namespace

double settle_free_fall_time(double top) {
    return std::sqrt(2.0 * top) + 1.0;
}

namespace {
/// Reads bed.count: one whole number per species, at least one particle, at most
/// kMaxRealizationParticles in all.
std::vector<long> read_counts(const Params& p, const DemScene& scene) {
    const auto counts = p.get<std::vector<double>>("count", Bounds::non_negative());
    if (counts.size() != scene.species.size())
        p.fail("count",
               fmt::format("has {} values for {} species", counts.size(), scene.species.size()),
               "one particle count per name in species.names");
    const std::string allowed =
        fmt::format("whole numbers >= 0 adding up to 1 .. {} particles", kMaxRealizationParticles);
    double total = 0;
    for (double c : counts) {
        if (std::trunc(c) != c) p.fail("count", "is not a list of whole numbers", allowed);
        total += c;
    }
    if (total < 1) p.fail("count", "adds up to no particles", allowed);
    if (total > static_cast<double>(kMaxRealizationParticles))
        p.fail("count",
               fmt::format("adds up to {:g} particles, more than one realization may hold", total),
               allowed);
    return {counts.begin(), counts.end()};
}

/// Fails on `key` when a settling stage of length `time` needs more than kMaxSettleSteps steps.
void check_settle_steps(const Params& p, const char* key, double time, double dt) {
    const double steps = std::ceil(time / dt);
    if (!(steps <= static_cast<double>(kMaxSettleSteps)))
        p.fail(key, fmt::format("makes a settling stage of {:.3g} steps of dt = {:g}", steps, dt),
               fmt::format("at most {} steps per settling stage, i.e. <= {:.4g} time units",
                           kMaxSettleSteps, static_cast<double>(kMaxSettleSteps) * dt));
}
}  // namespace

BedSpec BedSpec::from_params(const Params& p, const DemScene& scene) {
    BedSpec b;
    const std::string source = p.get_or_choice("source", "lattice", {"lattice", "lammps_data"});
    if (source == "lattice") {
        b.source = Source::lattice;
        b.count = read_counts(p, scene);
        const double d_max = scene.species.max_diameter();
        const double l_min = std::min(scene.domain.lx, scene.domain.ly);
        b.spacing = p.get_or<double>("spacing", 1.07 * d_max,
                                     Bounds::closed(d_max, std::max(d_max, l_min)));
        b.jitter = p.get_or<double>("jitter", 0.03, Bounds::non_negative());
        if (b.jitter >= 0.5 * (b.spacing - d_max) && b.jitter > 0)
            p.fail("jitter", "lets neighbouring lattice spheres overlap",
                   fmt::format("< (spacing - diameter)/2 = {:g}", 0.5 * (b.spacing - d_max)));
        // Initial agitation: a fluidized bed's particles move at 0.01-1 sqrt(g d_p); at 10, a
        // head-on collision at kn = 2e5 already overlaps by 1 % of d_p, and faster lattices
        // only blow up (1e6 crossed the box in one step).
        b.velocity_rms = p.get_or<double>("velocity_rms", 0.2, Bounds::closed(0.0, 10.0));
        const std::string layering =
            p.get_or_choice("layering", "mixed", {"mixed", "light_on_top", "heavy_on_top"});
        b.layering = layering == "light_on_top"   ? Layering::light_on_top
                     : layering == "heavy_on_top" ? Layering::heavy_on_top
                                                  : Layering::mixed;
        const double top = lattice_top(b, scene);
        if (scene.domain.has_lid() && top >= scene.domain.lid_height)
            p.fail("count",
                   fmt::format("needs a lattice {:.4g} high, above the lid at domain.lid = {:g}",
                               top, scene.domain.lid_height),
                   "fewer particles, a wider box or a higher domain.lid");
        if (top > kMaxDomainLength)
            p.fail("count", fmt::format("needs a lattice {:.4g} high", top),
                   fmt::format(
                       "a lattice at most {:g} high: fewer particles, a wider box or a smaller "
                       "bed.spacing",
                       kMaxDomainLength));
        b.settle = p.get_or<bool>("settle", true);
        // The settling protocol's keys are read (and checked) even with settle = false, so that
        // a scene can be run unsettled with one override, without editing out its settle block.
        const Params s = p.scope("settle");
        b.settle_damping = s.get_or<double>("damping", 1.0, Bounds::closed(0.0, 1e6));
        b.settle_damped_time =
            s.get_or<double>("damped_time", 7.2, Bounds::non_negative());  // steps bounded below
        // Kinetic energy per particle in m g d_p: a bed at rest is far below 1e-2; above 1,
        // settling would stop before it started. Below 1e-12 (speeds of 1e-6 sqrt(g d_p), the
        // level at which efdem calls a bed at rest) the test is one of rounding: settling would
        // run to bed.settle.max_time every time.
        b.settle_ke_threshold = s.get_or<double>("ke_threshold", 1e-6, Bounds::closed(1e-12, 1.0));
        b.settle_max_time =
            s.get_or<double>("max_time", 100.0, Bounds::positive());  // steps bounded below
        if (b.settle) {
            // Each settling stage is a bounded number of steps, checked here so that
            // `efdem --check` reports it without settling.
            check_settle_steps(p, "count", settle_free_fall_time(top), scene.dt);
            check_settle_steps(s, "damped_time", b.settle_damped_time, scene.dt);
            check_settle_steps(s, "max_time", b.settle_max_time, scene.dt);
        }
        // The settled beds of an earlier run of this scene (bed.write): read instead of built
        // and settled. The lattice's keys above are still read, so that the same scene serves
        // both runs, and bed.count checks the files.
        b.read = p.get_or_path("read", "");
        const Params r = p.scope("read");
        b.read_shared = r.get_or<bool>("shared", false);
        // As bed.velocity_rms: a fluidized bed's particles move at 0.01-1 sqrt(g d_p).
        b.read_velocity_rms = r.get_or<double>("velocity_rms", 0.0, Bounds::closed(0.0, 10.0));
        if (b.read.empty())
            for (const char* key : {"shared", "velocity_rms"})
                if (r.contains(key))
                    r.fail(key, "is given without bed.read",
                           "bed.read = NAME (the settled beds an earlier run wrote with "
                           "bed.write), or no bed.read.* key");
    } else {
        b.source = Source::lammps_data;
        b.file = p.get_path("file");
        b.settle = false;
        if (p.contains("read"))
            p.fail("read", "is for a lattice scene (bed.source = lattice)",
                   "with bed.source = lammps_data the bed is bed.file; bed.read replaces building "
                   "and settling the lattice of a scene that has one");
    }
    b.permute_species = p.get_or<bool>("permute_species", false);
    return b;
}

std::filesystem::path BedSpec::read_file(long r) const {
    return read_shared ? read : realization_file(read, r);
}

Particles lattice_bed(const BedSpec& bed, const DemScene& scene, const RealizationSpec& spec) {
    const LatticeGeometry g = lattice_geometry(bed, scene);
    const long n = g.n, nx = g.nx, ny = g.ny;
    const double ax = g.ax, ay = g.ay, az = g.az, z0 = g.z0;
    RandomStream packing(spec.seed, static_cast<std::uint64_t>(spec.realization), "packing");
    RandomStream velocities(spec.seed, static_cast<std::uint64_t>(spec.realization), "velocities");
    // Exact species counts: a random permutation of the labels (mixed), or stratified by density
    // (sites are filled from the bottom up, so the first labels end up lowest).
    std::vector<SpeciesId> order(bed.count.size());
    for (std::size_t s = 0; s < order.size(); ++s) order[s] = static_cast<SpeciesId>(s);
    if (bed.layering != BedSpec::Layering::mixed) {
        const bool heavy_first = bed.layering == BedSpec::Layering::light_on_top;
        std::stable_sort(order.begin(), order.end(), [&](SpeciesId a, SpeciesId b) {
            return heavy_first ? scene.species[a].density > scene.species[b].density
                               : scene.species[a].density < scene.species[b].density;
        });
    }
    std::vector<SpeciesId> labels;
    labels.reserve(static_cast<std::size_t>(n));
    for (SpeciesId s : order)
        labels.insert(labels.end(), static_cast<std::size_t>(bed.count[s]), s);
    if (bed.layering == BedSpec::Layering::mixed) packing.shuffle(labels.begin(), labels.end());
    const double sigma = bed.velocity_rms / std::sqrt(3.0);
    Particles p;
    p.reserve(static_cast<std::size_t>(n));
    for (long k = 0; k < n; ++k) {
        const long layer = k / (nx * ny), in_layer = k % (nx * ny);
        const double x = (static_cast<double>(in_layer % nx) + 0.5) * ax +
                         packing.uniform(-bed.jitter, bed.jitter);
        const double y = (static_cast<double>(in_layer / nx) + 0.5) * ay +
                         packing.uniform(-bed.jitter, bed.jitter);
        const double z =
            z0 + static_cast<double>(layer) * az + packing.uniform(-bed.jitter, bed.jitter);
        const Vec3 v{sigma * velocities.normal(), sigma * velocities.normal(),
                     sigma * velocities.normal()};
        p.add(k + 1, scene.domain.wrap({x, y, z}), v, labels[static_cast<std::size_t>(k)],
              scene.species);
    }
    return p;
}

void permute_species(Particles& p, const SpeciesTable& species, RandomStream& rng) {
    std::vector<SpeciesId> labels(p.species().begin(), p.species().end());
    rng.shuffle(labels.begin(), labels.end());
    for (std::size_t i = 0; i < labels.size(); ++i)
        p.set_species(static_cast<Index>(i), labels[i], species);
}

}  // namespace efdem::dem
