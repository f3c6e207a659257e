#include "mpi_driver/run/check_report.hpp"

#include <cmath>
#include <map>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/version.hpp"
#include "dem/scene.hpp"
#include "mpi_driver/run/ensemble_size.hpp"

namespace efdem::mpi_driver {

std::string check_report(const ParamTable& table, const RunSettings& settings,
                         const dem::System& sys, int n_ranks) {
    std::string out;
    auto line = [&out](const std::string& s) { out += s + "\n"; };
    line(fmt::format("efdem {} ({}) --check {}", version(), git_hash(), table.file()));
    line(fmt::format("mode: {}; ensemble: R = {}{}; seed {}", settings.mode_name(),
                     ensemble_size(n_ranks, settings.realizations_per_rank),
                     n_ranks == 1 ? " (--check --ranks=N: as run on N ranks)" : "", settings.seed));
    const auto& p = sys.particles();
    std::map<int, long> per_species;
    for (auto s : p.species()) ++per_species[s];
    std::string counts;
    for (const auto& [s, n] : per_species)
        counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ",
                              sys.species()[static_cast<dem::SpeciesId>(s)].name, n);
    const auto& d = sys.domain();
    line(fmt::format(
        "realization 0: {} particles ({}); box {} x {} periodic, floor z = 0, {}", p.size(), counts,
        d.lx, d.ly, d.has_lid() ? fmt::format("lid z = {}", d.lid_height) : std::string("no lid")));
    line("species:");
    for (std::size_t s = 0; s < sys.species().size(); ++s) {
        const auto id = static_cast<dem::SpeciesId>(s);
        line(fmt::format("  {}: density {}, diameter {}, mass {:.6f}, inertia {:.6f}",
                         sys.species()[id].name, sys.species()[id].density,
                         sys.species()[id].diameter, sys.species().mass(id),
                         sys.species().inertia(id)));
    }
    line("effects (applied in this order):");
    int k = 0;
    for (const auto& e : sys.effects()) {
        line(fmt::format("  {}. {}", ++k, e->name()));
        dem::EffectReport r;
        e->describe(r);
        for (const auto& [key, value] : r.lines) line(fmt::format("       {}: {}", key, value));
    }
    const double tc = sys.min_time_scale();
    if (std::isfinite(tc))
        line(
            fmt::format("time step: dt = {:g} = t_c/{:.1f}, shortest contact {} (t_c = {:.4g}); "
                        "refused above t_c/5 = {:.4g}, warned above t_c/20 = {:.4g}",
                        sys.dt(), tc / sys.dt(), sys.min_time_scale_label(), tc,
                        dem::kRefuseDtFraction * tc, dem::kWarnDtFraction * tc));
    else
        line(fmt::format("time step: dt = {:g} (no contact effect limits it)", sys.dt()));
    const dem::Needs n = sys.needs();
    std::vector<std::string> built, not_built;
    (n.neighbor_list ? built : not_built)
        .push_back(fmt::format("neighbour list{}",
                               sys.neighbor_list()
                                   ? fmt::format(" (skin {})", sys.neighbor_list()->skin())
                                   : std::string()));
    (n.contact_history ? built : not_built).push_back("contact history");
    (n.slab_fields ? built : not_built).push_back("slab fields");
    line(fmt::format("built: {}", built.empty() ? "nothing beyond the particles"
                                                : fmt::format("{}", fmt::join(built, ", "))));
    line(fmt::format("not built (no effect needs it): {}",
                     not_built.empty() ? "-" : fmt::format("{}", fmt::join(not_built, ", "))));
    const auto& o = settings.output;
    line(fmt::format("run file: {}", (o.directory / (o.prefix + ".h5")).string()));
    line(fmt::format("checkpoints: {}",
                     (settings.checkpoint.directory / (o.prefix + "_ckpt_NNNNNNNN.h5")).string()));
    line("parameters (value, origin):");
    for (const auto& r : table.resolved())
        line(fmt::format("  {} = {}   [{}]", r.key, r.value, r.origin));
    line("check passed: the scene is valid; nothing was run (settling skipped).");
    return out;
}

}  // namespace efdem::mpi_driver
