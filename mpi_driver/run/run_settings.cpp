#include "mpi_driver/run/run_settings.hpp"

#include <cmath>

#include <fmt/format.h>

namespace efdem::mpi_driver {

long whole_multiple(const Params& scope, const char* key, double duration, double dt,
                    const std::string& dt_name) {
    const double n = std::round(duration / dt);
    if (std::abs(n * dt - duration) > 1e-9 * std::max(duration, dt))
        scope.fail(key, fmt::format("is not a whole multiple of {} = {:g}", dt_name, dt),
                   fmt::format("a multiple of {:g}, e.g. {:g}", dt, std::max(1.0, n) * dt));
    return static_cast<long>(n);
}

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
    s.cpi.observable = cpi.get_or_choice("observable", "icdf", {"icdf", "compact"}) == "compact"
                           ? CpiSettings::Observable::compact
                           : CpiSettings::Observable::icdf;
    s.cpi.projection = cpi.get_or_choice("projection", "fixed", {"fixed", "periods"}) == "periods"
                           ? CpiSettings::Projection::periods
                           : CpiSettings::Projection::fixed;
    s.cpi.warmup = cpi.get_or<double>("warmup", 0.0, Bounds::non_negative());
    whole_multiple(cpi, "warmup", s.cpi.warmup, s.observe.interval, "observe.interval");
    s.cpi.healing = cpi.get_or<double>("healing", 10.0, Bounds::non_negative());
    whole_multiple(cpi, "healing", s.cpi.healing, s.observe.interval, "observe.interval");
    s.cpi.window = cpi.get_or<double>("window", 10.0, Bounds::positive());
    const long window_samples = whole_multiple(cpi, "window", s.cpi.window, s.observe.interval, "observe.interval");
    if (window_samples < 3)
        cpi.fail("window", fmt::format("holds {} samples; a slope needs at least 3", window_samples),
                 fmt::format(">= 3 x observe.interval = {:g}", 3 * s.observe.interval));
    // Both projections' keys are read, so switching cpi.projection on the command line works
    // on a scene written for the other one.
    s.cpi.dt = cpi.get_or<double>("dt", 80.0, Bounds::non_negative());
    s.cpi.periods = cpi.get_or<int>("periods", 2, Bounds::closed(0, 1000));
    s.cpi.max_extension = cpi.get_or<double>("max_extension", 30.0, Bounds::non_negative());
    whole_multiple(cpi, "max_extension", s.cpi.max_extension, s.observe.interval, "observe.interval");
    const std::string policy = cpi.get_or_choice("stability", "warn", {"warn", "halve", "stop"});
    s.cpi.stability = policy == "halve"  ? coarse::StabilityPolicy::halve_step
                      : policy == "stop" ? coarse::StabilityPolicy::stop
                                         : coarse::StabilityPolicy::warn;
    if (s.mode == Mode::cpi) {
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

    // Read in every run (get_or), so that a scene with a checkpoint block is valid whether or
    // not it checkpoints, and a restart may change these keys freely.
    const Params checkpoint = root.scope("checkpoint");
    s.checkpoint.interval = checkpoint.get_or<long>("interval", 0, Bounds::closed(0, 1000000000));
    s.checkpoint.keep = checkpoint.get_or<int>("keep", 2, Bounds::closed(1, 1000));
    s.checkpoint.directory = checkpoint.get_or_path("directory", s.output.directory);
    s.checkpoint.allow_physics_change = root.scope("restart").get_or<bool>("allow_physics_change", false);
    s.checkpoint.debug_delay = root.scope("debug").get_or<double>("checkpoint_delay", 0.0, Bounds::closed(0, 3600));
    return s;
}

}  // namespace efdem::mpi_driver
