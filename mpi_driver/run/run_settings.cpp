#include "mpi_driver/run/run_settings.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "coarse/demixing/observable_table.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "core/whole_multiple.hpp"
#include "dem/effect_registry.hpp"

namespace efdem::mpi_driver {

namespace {
/// Whether the observable named `name` can restrict one realization on its own (what a spread
/// over the realizations needs); an unknown name is refused where it is read.
bool restricts_members(const std::string& name, int quantiles) {
    const auto* row = coarse::observable_table().find(name);
    return !row || row->make(coarse::ProbabilityGrid(quantiles))->restricts_members();
}
}  // namespace

RunSettings RunSettings::from_params(const Params& root, const dem::DemScene& scene) {
    RunSettings s;
    const std::string mode =
        root.get_or_choice("mode", "direct", {"direct", "cpi", "steady", "continuation"});
    s.mode = mode == "cpi"            ? Mode::cpi
             : mode == "steady"       ? Mode::steady
             : mode == "continuation" ? Mode::continuation
                                      : Mode::direct;
    s.seed = root.get_or<std::uint64_t>("seed", 1);
    s.realizations_per_rank =
        root.scope("ensemble").get_or<int>("realizations_per_rank", 1, Bounds::closed(1, 4096));

    const Params observe = root.scope("observe");
    s.observe.interval = observe.get_or<double>("interval", 0.5, Bounds::open_closed(0.0, 1e6));
    s.observe.steps_per_sample =
        whole_multiple(observe, "interval", s.observe.interval, scene.dt, "dt");
    s.observe.quantiles = observe.get_or<int>("quantiles", 19, Bounds::closed(1, 999));
    s.observe.compact = observe.get_or<bool>("compact", false);
    std::vector<std::string> names;
    for (std::size_t k = 0; k < scene.species.size(); ++k)
        names.push_back(scene.species[static_cast<dem::SpeciesId>(k)].name);
    const std::string observed = observe.get_or_choice("species", names.front(), names);
    s.observe.species = static_cast<dem::SpeciesId>(scene.species.find(observed));
    s.observe.other = s.observe.species == 0 ? 1 : 0;
    s.observe.bed = observe.get_or<bool>("bed", false);
    if (s.observe.bed) {  // read only when on, so that a scene without it has nothing to explain
        s.observe.profile_dz =
            observe.get_or<double>("profile_dz", 1.0, Bounds::open_closed(0.0, 1e3));
        s.observe.profile_height =
            observe.get_or<double>("profile_height", 0.0, Bounds::closed(0.0, 1e6));
        s.observe.mixing_layer =
            observe.get_or<double>("mixing_layer", 2.0, Bounds::open_closed(0.0, 1e3));
    }

    const Params run = root.scope("run");
    if (s.is_steady()) {
        // A budget of DEM time, not a span to cover: the solve ends when it is spent.
        s.duration = run.get_or<double>("duration", 0.0, Bounds::closed(0.0, 1e9));
    } else {
        s.duration = run.get<double>("duration", Bounds::open_closed(0.0, 1e9));
        whole_multiple(run, "duration", s.duration, s.observe.interval, "observe.interval");
    }

    // The cpi block is read in both modes (a direct run of a cpi scene is the reference the cpi
    // run is compared with, and its cpi.* keys are not "unused"), but checked against the
    // sampling grid only in cpi mode: a direct run does not use them.
    const Params cpi = root.scope("cpi");
    const auto observables = coarse::observable_table().names();
    s.observable = cpi.get_or_choice("observable", observables.front(), observables);
    s.cpi = coarse::CpiSettings::from_params(cpi, s.observe.interval, s.is_cpi());
    const std::string lift = cpi.get_or_choice("lift", "mean", {"mean", "members", "own"});
    s.lift_members = lift != "mean";
    const bool own_states = restricts_members(s.observable, s.observe.quantiles);
    if (s.lift_members && s.is_cpi() && !own_states)
        cpi.fail("lift",
                 "= " + lift +
                     " moves each realization from its own coarse state, and cpi.observable = " +
                     s.observable + " cannot restrict a realization on its own",
                 "mean, or " + lift + " with cpi.observable = icdf or ranks");
    // A realization the gas no longer moves is in a state the DEM never leaves (U_s = 0.19: the
    // heavy spheres gather at the bottom and the bed defluidizes); a lift would move it on with
    // the others. hold leaves it where it is (EnsembleLifting), which needs its own coarse state.
    const std::string at_rest =
        cpi.get_or_choice("at_rest", own_states ? "hold" : "lift", {"hold", "lift"});
    if (at_rest == "hold" && s.is_cpi() && !own_states)
        cpi.fail("at_rest",
                 "= hold leaves a realization at rest where it is and moves the others by the "
                 "ensemble's increment, and cpi.observable = " +
                     s.observable + " cannot restrict a realization on its own",
                 "lift, or hold with cpi.observable = icdf or ranks");
    s.hold_at_rest = at_rest == "hold";
    // Where a bed has partly come to rest, a relabelling there kicks it back into motion
    // (bench/lift_restart.py): moving relabels the moving particles of each height interval first.
    // In a segregating bed the lights gather with lights (bench/results/lift_clusters.md):
    // clustered adds lights where lights are and takes away the isolated ones (it overshoots:
    // the lifted beds then rise faster than the direct ones); like_lights draws the new lights
    // with the neighbourhoods the interval's lights have; keep_clusters adds them so and removes
    // the lone lights first (a jump's lifts mostly remove lights from the lower bed, and a random
    // removal thins its clusters: bench/results/lift_clusters.md section 4).
    const std::string relabel = cpi.get_or_choice(
        "relabel", "any", {"any", "moving", "clustered", "like_lights", "keep_clusters"});
    s.relabel_by = relabel == "moving"          ? coarse::SwitchOrder::By::moving
                   : relabel == "clustered"     ? coarse::SwitchOrder::By::light_neighbours
                   : relabel == "like_lights"   ? coarse::SwitchOrder::By::like_lights
                   : relabel == "keep_clusters" ? coarse::SwitchOrder::By::keep_clusters
                                                : coarse::SwitchOrder::By::any;
    // A node of the ICDF is the mean of two particles' heights: which particles of an interval
    // end as its lowest and highest light ones decides how far the lift misses it (the lift's
    // error is charged to the jump, docs/error_control.md §6). matched picks them; random is
    // the paper's minimal relabelling.
    s.relabel_at_nodes =
        cpi.get_or_choice("relabel_nodes", "matched", {"matched", "random"}) == "matched";
    // Each species rises or sinks at its own mean velocity: a relabelled particle that keeps its
    // velocity carries the old species' drift into the new one until drag and contacts restore
    // it (bench/results/lift_velocity.md); species moves it to the new species' local mean.
    s.carry_species_velocity =
        cpi.get_or_choice("relabel_velocity", "kept", {"kept", "species"}) == "species";
    // positions: a bed of two sizes is lifted by exchanging particles between heights
    // (docs/lifting_by_positions.md); colours switch labels in place (equal sizes only).
    s.lift_by_positions =
        cpi.get_or_choice("lift_by", "colours", {"colours", "positions"}) == "positions";
    // How far the relaxation after an exchange may move a height (docs/lifting_by_positions.md):
    // the lift's accuracy against the relaxations that can finish in a packed region.
    if (s.lift_by_positions) {
        s.lift_height_band =
            cpi.get_or<double>("lift_height_band", 0.25, Bounds::open_closed(0.0, 2.0));
        // The large species observed: how far each of its particles may end from its rank's
        // height after the exchange (docs/lifting_by_positions.md "Rank by rank").
        s.lift_resolution =
            cpi.get_or<double>("lift_resolution", 0.1, Bounds::open_closed(0.0, 1.0));
    }
    if (s.lift_by_positions && s.relabel_by != coarse::SwitchOrder::By::any)
        cpi.fail("relabel",
                 "= " + relabel +
                     " chooses which labels a colour lift switches, and cpi.lift_by = "
                     "positions switches none",
                 "any with cpi.lift_by = positions, or cpi.lift_by = colours");
    if (s.lift_by_positions && s.carry_species_velocity)
        cpi.fail("relabel_velocity",
                 "= species moves the velocities of relabelled particles, and cpi.lift_by = "
                 "positions relabels none (it moves particles with their velocities)",
                 "kept with cpi.lift_by = positions, or cpi.lift_by = colours");
    if (s.lift_by_positions && s.is_steady())
        cpi.fail("lift_by",
                 "= positions can fail to relax its overlaps, which only an adaptive cpi run "
                 "handles (as a rejected jump); the steady solvers lift to every iterate",
                 "colours in mode = steady or continuation");
    if (s.lift_by_positions && s.is_cpi() &&
        s.cpi.projection != coarse::CpiSettings::Projection::adaptive)
        cpi.fail("lift_by",
                 "= positions can fail to relax its overlaps, which only cpi.projection = "
                 "adaptive handles (as a rejected jump, redone shorter)",
                 "positions with cpi.projection = adaptive, or colours");
    // own: each realization jumps with its own slope (the multistep integrator measures them).
    s.cpi.multistep.lift_apart = lift == "own";
    // cpi.accuracy measures the ensemble's noise from every burst whose members a lift kept apart.
    s.cpi.multistep.spread_survives_lift = s.lift_members;
    if (lift == "own" && s.cpi.projection == coarse::CpiSettings::Projection::periods)
        cpi.fail("lift",
                 "= own moves each realization by its own slope's jump, which cpi.projection = "
                 "periods does not measure",
                 "mean or members with cpi.projection = periods; own with fixed or adaptive");
    if (lift == "own" && s.cpi.multistep.pooled_curvature)
        cpi.fail("lift",
                 "= own moves each realization by its own slope's deviation, assumed to persist "
                 "from burst to burst, and cpi.curvature = pooled adds the ensemble's curvature "
                 "only, fitted on the assumption that the bursts' slope errors are independent",
                 "mean or members with cpi.curvature = pooled; own with cpi.curvature = none");
    // cpi.hand_off = steady: the CPI run's end state goes to the steady solver. Read in both
    // modes like the other cpi keys (its steady.* keys then too); a direct run does not use it.
    s.hand_off = cpi.get_or_choice("hand_off", "none", {"none", "steady"}) == "steady";
    if (s.lift_by_positions && s.hand_off)
        cpi.fail("hand_off",
                 "= steady hands the end state to the steady solver, which lifts to every "
                 "iterate, and cpi.lift_by = positions can fail to relax its overlaps there",
                 "none with cpi.lift_by = positions");
    if (s.is_steady() || s.hand_off) {
        const auto* row = coarse::observable_table().find(s.observable);
        const long dimension =
            row ? static_cast<long>(
                      row->make(coarse::ProbabilityGrid(s.observe.quantiles))->dimension())
                : s.observe.quantiles;
        // The parameters a continuation may follow: the keys the effects' registry rows list as
        // changeable during a run, with the bounds each effect reads its key with.
        std::vector<coarse::ContinuationParameter> parameters;
        for (const dem::EffectParameter& p : dem::run_parameters())
            parameters.push_back({p.key, p.parameter.bounds});
        s.steady = coarse::SteadyRunSettings::from_params(
            root, s.observe.interval, dimension,
            s.mode == Mode::continuation ? coarse::SteadyRunSettings::Use::continuation
            : s.is_steady()              ? coarse::SteadyRunSettings::Use::steady
                                         : coarse::SteadyRunSettings::Use::hand_off,
            parameters, [&](const std::string& key) {
                const dem::EffectParameter p = *dem::find_run_parameter(key);
                if (std::find(scene.effect_names.begin(), scene.effect_names.end(), p.effect) ==
                    scene.effect_names.end())
                    root.scope("continuation")
                        .fail(
                            "parameter",
                            fmt::format("names a key of {}, which the scene's effects do not list",
                                        p.effect),
                            fmt::format("a key of a listed effect (add {} to effects)", p.effect));
                return root.scope(std::string(p.effect))
                    .get<double>(std::string(p.parameter.key), p.parameter.bounds);
            });
        if (s.steady.gap_coordinates && s.observable != "icdf" && s.observable != "ranks")
            root.scope("steady").fail(
                "coordinates",
                "= gaps are coordinates of an ICDF, and cpi.observable is " + s.observable,
                "heights, or gaps with cpi.observable = icdf or ranks");
    }
    if (s.lifts()) {
        // After cpi.warmup and one burst something must be left to jump over: a run of exactly
        // warm-up + one burst is a direct run (ProjectiveRun warns of the cases only the run
        // itself can tell: a steady warm-up to the end, a controller that declines every jump).
        const double least = s.cpi.warmup + s.cpi.burst();
        if (s.is_cpi() && s.duration <= least + 1e-9 * least)
            run.fail("duration",
                     fmt::format("leaves nothing to jump after cpi.warmup + one burst (cpi.healing "
                                 "+ cpi.window) = "
                                 "{:g}: the cpi run could not make a single projective jump",
                                 least),
                     fmt::format("run.duration > {:g} (several bursts and jumps to gain anything), "
                                 "or mode = direct",
                                 least));
        if (scene.species.size() != 2)
            root.fail("mode",
                      fmt::format("{} lifts by swapping the labels of two species, but "
                                  "species.names lists {}",
                                  s.mode_name(), scene.species.size()),
                      "direct, or exactly two species");
        for (std::size_t k = 1; k < scene.species.size() && !s.lift_by_positions; ++k)
            if (scene.species[static_cast<dem::SpeciesId>(k)].diameter != scene.species[0].diameter)
                root.scope("species").fail(
                    "diameter",
                    "differs between species: swapping labels would create overlaps "
                    "(physics.md §9)",
                    "equal diameters in cpi mode with cpi.lift_by = colours (the default), or "
                    "cpi.lift_by = positions, which exchanges particles between heights");
    }

    const Params output = root.scope("output");
    s.output.directory = output.get_or_path("directory", ".");
    s.output.prefix = output.get_or<std::string>("prefix", "efdem");
    if (s.output.prefix.find('/') != std::string::npos)
        output.fail("prefix", "contains '/'", "a file stem; set output.directory for the folder");
    // File names are at most 255 bytes, and the longest name made from the prefix adds 21
    // (PREFIX_r0000_000000.vtp.tmp, PREFIX_ckpt_00000000.h5.tmp).
    if (s.output.prefix.empty() || s.output.prefix.size() > 200 || s.output.prefix == "." ||
        s.output.prefix == "..")
        output.fail("prefix", fmt::format("is {} characters long", s.output.prefix.size()),
                    "a file stem of 1 to 200 characters, not . or ..");
    if (s.output.directory.string().size() > 3000)
        output.fail("directory",
                    fmt::format("is {} characters long", s.output.directory.string().size()),
                    "a path of at most 3000 characters");
    s.output.bed_write = root.scope("bed").get_or_path("write", "");
    s.output.vtk_interval = output.get_or<double>("vtk_interval", 0.0, Bounds::closed(0.0, 1e9));
    if (s.output.vtk_interval > 0)
        whole_multiple(output, "vtk_interval", s.output.vtk_interval, s.observe.interval,
                       "observe.interval");
    s.output.thermo_interval =
        output.get_or<double>("thermo_interval", 0.0, Bounds::closed(0.0, 1e9));
    if (s.output.thermo_interval > 0)
        whole_multiple(output, "thermo_interval", s.output.thermo_interval, s.observe.interval,
                       "observe.interval");

    s.output.overwrite = output.get_or<bool>("overwrite", false);
    s.checkpoint = CheckpointSettings::from_params(root, s.output.directory);
    if (s.is_steady() && s.checkpoint.enabled())
        root.scope("checkpoint")
            .fail("interval",
                  fmt::format("is not supported with mode = {}: a solve keeps micro states in "
                              "memory that a checkpoint does not hold",
                              s.mode_name()),
                  "0 (the default) with mode = steady or continuation");
    const Params debug = root.scope("debug");
    s.injected_failure.realization =
        debug.get_or<long>("fail_realization", -1, Bounds::closed(-1, 1e9));
    s.injected_failure.time = debug.get_or<double>("fail_time", 0.0, Bounds::closed(0.0, 1e9));
    s.injected_failure.keep_stage =
        debug.get_or_choice("fail_stage", "sample", {"sample", "keep"}) == "keep";

    const Params ensemble = root.scope("ensemble");
    const std::string action =
        ensemble.get_or_choice("on_failure", "abort", {"abort", "drop", "replace"});
    s.on_failure.action = action == "drop"      ? FailurePolicy::Action::drop
                          : action == "replace" ? FailurePolicy::Action::replace
                                                : FailurePolicy::Action::abort;
    if (s.solves_steady() && s.on_failure.action != FailurePolicy::Action::abort)
        ensemble.fail(
            "on_failure",
            fmt::format(
                "is not supported with {}: the solve compares evaluations of the same ensemble, "
                "which a dropped or replaced realization would change",
                s.steady_solve_key()),
            "abort with mode = steady or continuation, or with cpi.hand_off = steady");
    if (s.on_failure.action == FailurePolicy::Action::replace && !s.is_cpi())
        ensemble.fail(
            "on_failure",
            "= replace needs cpi mode: in a direct run a copy of a healthy realization would "
            "follow "
            "its donor's trajectory (the DEM is deterministic) and correlate the ensemble",
            "abort or drop in direct mode; abort, drop or replace in cpi mode");
    // A realization at rest stays so (nothing in the DEM moves a bed the gas no longer lifts):
    // advancing it computes nothing but floating-point drift of ~1e-13 d_p per sample.
    s.pause_at_rest = ensemble.get_or_choice("at_rest", "pause", {"pause", "simulate"}) == "pause";
    s.on_failure.max_failures = ensemble.get_or<long>("max_failures", -1, Bounds::closed(-1, 1e9));
    if (s.on_failure.action == FailurePolicy::Action::abort && ensemble.contains("max_failures"))
        ensemble.fail("max_failures", "is read only with ensemble.on_failure = drop or replace",
                      "remove it, or set ensemble.on_failure");
    return s;
}

const char* RunSettings::mode_name() const {
    switch (mode) {
        case Mode::direct:
            return "direct";
        case Mode::cpi:
            return "cpi";
        case Mode::steady:
            return "steady";
        case Mode::continuation:
            return "continuation";
    }
    return "?";
}

std::string RunSettings::steady_solve_key() const {
    return is_steady() ? fmt::format("mode = {}", mode_name()) : "cpi.hand_off = steady";
}

void RunSettings::check_ensemble(const Params& root, int realizations) {
    // A run that measures the spread of the realizations' slopes needs two of them to the end.
    const bool spread = is_cpi() && cpi.projection == coarse::CpiSettings::Projection::adaptive;
    on_failure.min_active = spread ? 2 : 1;
    if (on_failure.max_failures < 0) on_failure.max_failures = std::max(1, realizations / 4);
    if (on_failure.action == FailurePolicy::Action::drop &&
        on_failure.max_failures > realizations - on_failure.min_active)
        on_failure.max_failures = std::max(0, realizations - on_failure.min_active);
    if (solves_steady()) {
        // The key that asked for the solve: the mode, or the hand-off of a cpi run.
        const bool by_mode = is_steady();
        const std::string asked = steady_solve_key();
        if (realizations < 2) {
            const std::string why = fmt::format(
                "{} stops its solve at the noise level of the ensemble, measured from the spread "
                "of >= 2 realizations; this run has {} (ranks x ensemble.realizations_per_rank)",
                by_mode ? fmt::format("= {}", mode_name()) : std::string("= steady"), realizations);
            const std::string allowed =
                by_mode ? "steady or continuation with >= 2 realizations (more ranks or "
                          "ensemble.realizations_per_rank)"
                        : "none, or steady with >= 2 realizations (more ranks or "
                          "ensemble.realizations_per_rank)";
            if (by_mode)
                root.fail("mode", why, allowed);
            else
                root.scope("cpi").fail("hand_off", why, allowed);
        }
        if (!restricts_members(observable, observe.quantiles))
            root.scope("cpi").fail(
                "observable",
                fmt::format("cannot restrict a realization on its own, and {} measures the "
                            "noise of F from the realizations' spread",
                            asked),
                fmt::format("icdf or ranks with {}", asked));
    }
    if (!spread) return;
    const Params c = root.scope("cpi");
    if (realizations < 2)
        c.fail("projection",
               fmt::format("needs at least 2 realizations to measure the statistical error of the "
                           "slope from their "
                           "spread; this run has {} (ranks x ensemble.realizations_per_rank)",
                           realizations),
               "fixed or periods with one realization; adaptive with >= 2 (more ranks or "
               "ensemble.realizations_per_rank)");
    if (!restricts_members(observable, observe.quantiles))
        c.fail(
            "observable",
            "cannot restrict a realization on its own, and cpi.projection = adaptive needs every "
            "realization's own slope",
            "icdf or ranks with cpi.projection = adaptive");
}

}  // namespace efdem::mpi_driver
