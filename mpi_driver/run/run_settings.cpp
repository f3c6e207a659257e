#include "mpi_driver/run/run_settings.hpp"

#include <fmt/format.h>

#include "coarse/demixing/observable_table.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "core/whole_multiple.hpp"

namespace efdem::mpi_driver {

RunSettings RunSettings::from_params(const Params& root, const dem::DemScene& scene) {
    RunSettings s;
    s.mode = root.get_or_choice("mode", "direct", {"direct", "cpi"}) == "cpi" ? Mode::cpi : Mode::direct;
    s.seed = root.get_or<std::uint64_t>("seed", 1);
    s.realizations_per_rank =
        root.scope("ensemble").get_or<int>("realizations_per_rank", 1, Bounds::closed(1, 4096));

    const Params observe = root.scope("observe");
    s.observe.interval = observe.get_or<double>("interval", 0.5, Bounds::positive());
    s.observe.steps_per_sample = whole_multiple(observe, "interval", s.observe.interval, scene.dt, "dt");
    s.observe.quantiles = observe.get_or<int>("quantiles", 19, Bounds::closed(1, 999));
    s.observe.compact = observe.get_or<bool>("compact", false);
    std::vector<std::string> names;
    for (std::size_t k = 0; k < scene.species.size(); ++k) names.push_back(scene.species[static_cast<dem::SpeciesId>(k)].name);
    const std::string observed = observe.get_or_choice("species", names.front(), names);
    s.observe.species = static_cast<dem::SpeciesId>(scene.species.find(observed));
    s.observe.other = s.observe.species == 0 ? 1 : 0;

    const Params run = root.scope("run");
    s.duration = run.get<double>("duration", Bounds::positive());
    whole_multiple(run, "duration", s.duration, s.observe.interval, "observe.interval");

    // The cpi block is read and checked in both modes: a direct run of a cpi scene is the
    // reference that the cpi run is compared with (and its cpi.* keys are not "unused").
    const Params cpi = root.scope("cpi");
    const auto observables = coarse::observable_table().names();
    s.observable = cpi.get_or_choice("observable", observables.front(), observables);
    s.cpi = coarse::CoarseRunSettings::from_params(cpi, s.observe.interval);
    if (s.is_cpi()) {
        if (scene.species.size() != 2)
            root.fail("mode", fmt::format("cpi lifts by swapping the labels of two species, but "
                                          "species.names lists {}", scene.species.size()),
                      "direct, or exactly two species");
        for (std::size_t k = 1; k < scene.species.size(); ++k)
            if (scene.species[static_cast<dem::SpeciesId>(k)].diameter != scene.species[0].diameter)
                root.scope("species").fail("diameter", "differs between species: swapping labels would "
                                                       "create overlaps (physics.md §9)",
                                           "equal diameters in cpi mode");
    }

    const Params output = root.scope("output");
    s.output.directory = output.get_or_path("directory", ".");
    s.output.prefix = output.get_or<std::string>("prefix", "efdem");
    if (s.output.prefix.find('/') != std::string::npos)
        output.fail("prefix", "contains '/'", "a file stem; set output.directory for the folder");
    s.output.vtk_interval = output.get_or<double>("vtk_interval", 0.0, Bounds::non_negative());
    if (s.output.vtk_interval > 0)
        whole_multiple(output, "vtk_interval", s.output.vtk_interval, s.observe.interval, "observe.interval");
    s.output.thermo_interval = output.get_or<double>("thermo_interval", 0.0, Bounds::non_negative());
    if (s.output.thermo_interval > 0)
        whole_multiple(output, "thermo_interval", s.output.thermo_interval, s.observe.interval, "observe.interval");

    s.output.overwrite = output.get_or<bool>("overwrite", false);
    s.checkpoint = CheckpointSettings::from_params(root, s.output.directory);
    const Params debug = root.scope("debug");
    s.injected_failure.realization = debug.get_or<long>("fail_realization", -1);
    s.injected_failure.time = debug.get_or<double>("fail_time", 0.0);
    return s;
}

void RunSettings::check_ensemble(const Params& root, int realizations) const {
    if (!is_cpi() || cpi.projection != coarse::CoarseRunSettings::Projection::adaptive) return;
    const Params c = root.scope("cpi");
    if (realizations < 2)
        c.fail("projection",
               fmt::format("needs at least 2 realizations to measure the statistical error of the slope from their "
                           "spread; this run has {} (ranks x ensemble.realizations_per_rank)", realizations),
               "fixed or periods with one realization; adaptive with >= 2 (more ranks or "
               "ensemble.realizations_per_rank)");
    const coarse::ProbabilityGrid grid(observe.quantiles);
    const auto* row = coarse::observable_table().find(observable);
    if (row && !row->make(grid)->restricts_members())
        c.fail("observable", "cannot restrict a realization on its own, and cpi.projection = adaptive needs every "
                             "realization's own slope",
               "icdf with cpi.projection = adaptive");
}

}  // namespace efdem::mpi_driver
