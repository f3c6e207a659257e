// efdem: wiring only. Parse the command line, read the scene collectively, build this rank's
// realizations, then hand over to the driver of the chosen mode.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "coarse/demixing/probability_grid.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "core/version.hpp"
#include "dem/beds/bed_diagnostics.hpp"
#include "dem/beds/bed_observation.hpp"
#include "dem/effect_registry.hpp"
#include "dem/realization_builder.hpp"
#include "mpi_driver/ensemble/dem_realization.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"
#include "mpi_driver/output/csv_recorder.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"
#include "mpi_driver/run/check_report.hpp"
#include "mpi_driver/run/driver.hpp"
#include "mpi_driver/run/steady_driver.hpp"
#if EFDEM_HAVE_HDF5
#include "mpi_driver/checkpoint/checkpoint_reader.hpp"
#include "mpi_driver/checkpoint/checkpoint_writer.hpp"
#include "mpi_driver/output/hdf5_recorder.hpp"
#endif
#include "mpi_driver/checkpoint/restart_check.hpp"
#include "mpi_driver/checkpoint/restart_loader.hpp"
#include "mpi_driver/output/recorder_list.hpp"
#include "mpi_driver/parallel/mpi_broadcast.hpp"
#include "mpi_driver/parallel/mpi_session.hpp"
#include "mpi_driver/parallel/scene_input.hpp"
#include "mpi_driver/parallel/stop_signal.hpp"
#include "mpi_driver/run/output_guard.hpp"
#include "mpi_driver/run/run_observables.hpp"
#include "mpi_driver/run/run_options.hpp"
#include "mpi_driver/run/run_settings.hpp"
#include "mpi_driver/run/settling_progress.hpp"

using namespace efdem;
using namespace efdem::mpi_driver;

namespace {
/// observe.bed: how every realization measures the bed (the same on every rank: the profile's
/// default top depends only on the particle count and sizes, which every realization shares).
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

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

/// The root's wall clock outside the run loop: since start-up, and the set-up's settling.
struct SetupWall {
    Clock::time_point start = Clock::now();
    double settling_seconds = 0;

    void fill(RunSummary& s) const {
        s.settling_wall_seconds = settling_seconds;
        s.total_wall_seconds = seconds_since(start);
    }
};

/// `bed`: the run's bed_settings (the axes of /bed), if it records them.
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
    p.ranks = mpi.size();
    p.realizations_per_rank = s.realizations_per_rank;
    p.realizations = mpi.size() * s.realizations_per_rank;
    p.seed = s.seed;
    p.p_grid = coarse::ProbabilityGrid(s.observe.quantiles).values();
    p.observed_species = any.species()[s.observe.species].name;
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

/// Runs the scene: the root drives (direct or cpi loop) and records; the other ranks serve.
/// `restart`: the checkpoint to continue from (null: a new run).
int run(const MpiSession& mpi, const ParamTable& table, const RunSettings& s,
        std::vector<dem::System> systems, const RestartData* restart, const SetupWall& wall) {
    const std::optional<dem::BedObservationSettings> bed = bed_settings(s, systems.front());
    const RunProvenance prov = provenance(mpi, table, s, systems.front(), bed);
    const EnsembleLayout layout(mpi.world(), s.realizations_per_rank);
    RunObservables observables = RunObservables::from_settings(s);

    std::unique_ptr<RecorderList> recorders;
    std::vector<std::unique_ptr<Realization>> local;
    const bool resume = restart != nullptr;
    try {
        if (mpi.is_root()) {
            if (resume) restore_outputs(restart->header, s.output.directory, s.output.prefix);
            std::vector<std::unique_ptr<RunRecorder>> owned;
#if EFDEM_HAVE_HDF5
            owned.push_back(std::make_unique<Hdf5Recorder>(s.output.directory, s.output.prefix,
                                                           prov, observables.primary->dimension(),
                                                           resume));
#endif
            owned.push_back(
                std::make_unique<CsvRecorder>(s.output.directory, s.output.prefix, prov, resume));
            recorders = std::make_unique<RecorderList>(std::move(owned));
        }
        RealizationOutput out{
            s.output.directory, s.output.prefix,
            std::lround(s.output.vtk_interval / s.observe.interval),
            std::lround(s.output.thermo_interval / s.observe.interval),
            resume ? fmt::format("_cont{:08d}", restart->header.stepper.samples_taken) : ""};
        for (auto& sys : systems)
            local.push_back(std::make_unique<DemRealization>(std::move(sys), s.observe.species,
                                                             s.observe.other, out, resume, bed));
    } catch (const std::exception& e) {
        mpi.abort(e.what(), kExitRuntimeFailure);
    }
    if (resume) {
        // A state that does not fit the scene's realizations (another bed) is an input error.
        int code = kExitOk;
        std::string message;
        try {
            const auto& active = restart->header.stepper.active;
            for (std::size_t j = 0; j < local.size(); ++j) {
                const auto r = static_cast<std::size_t>(local[j]->index());
                // A realization dropped after a failure stays as built: it is never advanced again.
                if (!active.empty() && active[r] == 0) continue;
                local[j]->restore_state(restart->local[j]);
            }
        } catch (const std::exception& e) {
            code = kExitInputError;
            message = fmt::format("{}: checkpoint does not fit the scene: {}",
                                  restart->path.string(), e.what());
        }
        const Agreement agreed = agree_on_failure(mpi.comm(), code, message);
        if (agreed.exit_code != kExitOk) {
            if (mpi.is_root()) log::error("{}", agreed.message);
            return agreed.exit_code;
        }
        log::info("restarted from {} at t = {:.6g}", restart->path.string(), local.front()->time());
    }
    log::info(
        "efdem {}: {} run of {} on {} ranks x {} = {} realizations ({} particles each), output "
        "{}/{}.*",
        version(), prov.mode, table.file(), mpi.size(), s.realizations_per_rank, prov.realizations,
        local.front()->particles(), s.output.directory.string(), s.output.prefix);

    StepperSettings ss;
    ss.sample_interval = s.observe.interval;
    ss.steps_per_sample = s.observe.steps_per_sample;
    ss.quantiles = s.observe.quantiles;
    ss.seed = s.seed;
    ss.failure = s.injected_failure;
    ss.on_failure = s.on_failure;
    ss.recorded = observables.recorded.get();
    ss.bed = bed;
    ss.parameter = s.steady.parameter;
    ss.lift_members = s.lift_members && s.is_cpi();
    // The run's start (progress counts from there; on the non-root ranks it is not used).
    const double t0 =
        resume && mpi.is_root() ? restart->header.driver.t_origin : local.front()->time();
    Progress progress(t0, t0 + s.duration, 2.0);
    const ColourLifter lifter;
    // A steady solve goes back in time (kept states): its progress is per iterate (steady_driver).
    EnsembleStepper stepper(layout, std::move(local), ss, *observables.primary, lifter,
                            recorders.get(), mpi.is_root() && !s.is_steady() ? &progress : nullptr);
    RunControl control;
    if (resume) {
        stepper.restore_state(restart->header.stepper);
        control.resume = restart->header.driver;
    }
#if EFDEM_HAVE_HDF5
    // Always a writer: a stop signal checkpoints even a run without periodic checkpoints.
    std::unique_ptr<CheckpointWriter> writer;
    {
        CheckpointHeader identity;
        identity.mode = prov.mode;
        identity.realizations = prov.realizations;
        identity.scene_text = table.text();
        identity.parameters = parameter_lines(table);
        // The recorders (root only) name the files they write; the checkpoint stores them whole.
        writer = std::make_unique<CheckpointWriter>(
            layout, s.checkpoint, s.output.prefix, std::move(identity),
            recorders ? recorders->files() : std::vector<std::filesystem::path>{});
        stepper.set_checkpoint_writer(writer.get(), s.checkpoint.enabled());
        control.checkpoint_interval = s.checkpoint.interval;
    }
#endif
    if (!mpi.is_root()) {
        try {
            stepper.serve();
        } catch (const RunFailed&) {
            return kExitRuntimeFailure;  // the failing rank said why; the root marks the run file
        }
        return stepper.finish_code();
    }
    RunSummary summary;
    try {
        summary = s.is_steady() ? run_steady(stepper, s, recorders.get(), progress)
                  : s.is_cpi()  ? run_cpi(stepper, s, observables.fallback.get(), recorders.get(),
                                          progress, control)
                                : run_direct(stepper, s, progress, control);
        wall.fill(summary);
        recorders->finish(summary);
    } catch (const RunFailed& e) {
        summary.end_status = std::string("failed: ") + e.what();
        summary.simulated_time = stepper.time() - t0;
        summary.dem_time = stepper.micro_time();
        summary.particle_steps = stepper.particle_steps();
        summary.wall_seconds = progress.elapsed_seconds();
        wall.fill(summary);
        try {
            recorders->finish(summary);
        } catch (const std::exception& again) {
            log::error("the run file could not be marked failed: {}", again.what());
        }
        log::error("the run failed; its files in {} are marked 'failed'",
                   s.output.directory.string());
        return kExitRuntimeFailure;
    } catch (const std::exception& e) {
        // A failure on the root (e.g. its run file on a full disk): mark the run file if it can
        // be (finish() frees its reserve first), then end every rank.
        summary.end_status = std::string("failed: ") + e.what();
        wall.fill(summary);
        try {
            recorders->finish(summary);
        } catch (const std::exception&) {
        }
        mpi.abort(e.what(), kExitRuntimeFailure);
    }
    log::info(
        "{}: simulated {:.6g} time units ({:.6g} by the DEM) in {} wall ({} settling the beds, {} "
        "the run), "
        "{:.3e} particle-steps",
        summary.end_status, summary.simulated_time, summary.dem_time,
        format_duration(summary.total_wall_seconds), format_duration(summary.settling_wall_seconds),
        format_duration(summary.wall_seconds), summary.particle_steps);
    if (summary.stop_signal != 0) {
        if (s.is_steady()) {
            std::fprintf(stderr,
                         "efdem: stopped by %s; the iterates so far and the best one are in "
                         "%s/%s.h5 (mode = "
                         "%s cannot be continued from a checkpoint)\n",
                         signal_name(summary.stop_signal).c_str(), s.output.directory.c_str(),
                         s.output.prefix.c_str(), s.mode_name());
        } else if (summary.checkpoint.empty()) {
            std::fprintf(stderr, "efdem: stopped by %s; nothing could be saved (no HDF5)\n",
                         signal_name(summary.stop_signal).c_str());
        } else {
            std::string command = fmt::format("mpirun -n {} efdem {}", mpi.size(), table.file());
            for (const auto& o : table.overrides()) command += " " + o;
            std::fprintf(
                stderr,
                "efdem: stopped by %s: checkpoint %s (t = %.6g); continue with: %s restart=%s\n",
                signal_name(summary.stop_signal).c_str(), summary.checkpoint.c_str(),
                summary.checkpoint_time, command.c_str(), summary.checkpoint.c_str());
        }
        std::fflush(stderr);
        return kExitInterrupted;
    }
    return summary.unconverged ? kExitRuntimeFailure : kExitOk;
}

void print_effects() {
    std::printf("effects a scene can list (effects = name name ...):\n");
    for (const auto& e : dem::effect_registry().entries())
        std::printf("  %-16.*s %.*s\n", static_cast<int>(e.name.size()), e.name.data(),
                    static_cast<int>(e.summary.size()), e.summary.data());
    std::printf("documentation: docs/effects/<name>.md\n");
}
}  // namespace

int main(int argc, char** argv) {
    MpiSession mpi(&argc, &argv);
    SetupWall wall;
    log::configure(mpi.rank(), mpi.size(), log::Level::info);
    // From here on a stop signal is held until the run reaches a safe point (stop_signal.hpp).
    install_stop_signal_handlers();

    RunOptions options;
    try {
        options = RunOptions::parse(argc, argv);
    } catch (const InputError& e) {
        if (mpi.is_root()) log::error("{}", e.what());
        return kExitInputError;
    }
    switch (options.action) {
        case RunOptions::Action::help:
            if (mpi.is_root()) std::printf("%s", RunOptions::usage().c_str());
            return kExitOk;
        case RunOptions::Action::version:
            if (mpi.is_root())
                std::printf("efdem %s (git %s; %s)\n", version().c_str(), git_hash().c_str(),
                            build_info().c_str());
            return kExitOk;
        case RunOptions::Action::list_effects:
            if (mpi.is_root()) print_effects();
            return kExitOk;
        default:
            break;
    }
    if (const std::string mismatch = mpi.launcher_mismatch(); !mismatch.empty()) {
        log::error("{}", mismatch);
        return kExitInputError;
    }

    // Set-up: every rank reads the same scene and builds its realizations. Failures are agreed
    // on collectively, so that all ranks stop together and the root prints one message.
    const bool list_keys = options.action == RunOptions::Action::list_keys;
    const bool check = options.action == RunOptions::Action::check || list_keys;
    const int ranks = options.ranks > 0 ? options.ranks : mpi.size();  // --ranks=N with --check
    int code = kExitOk;
    std::string message;
    std::optional<ParamTable> table;
    std::optional<RunSettings> settings;
    std::vector<dem::System> systems;
    const Clock::time_point settling_start = Clock::now();
    try {
        table.emplace(read_scene(mpi, options.scene, options.overrides));
        Params root = table->root();
        const dem::DemScene scene = dem::DemScene::from_params(root);
        settings = RunSettings::from_params(root, scene);
        settings->check_ensemble(root, ranks * settings->realizations_per_rank);
        const int k = check ? 1 : settings->realizations_per_rank;
        // Settling a paper-size bed takes minutes: the root says how its own realizations go
        // (the other ranks settle theirs at the same time).
        SettlingProgressLine settling_line(5.0);
        const dem::SettlingReport settling =
            mpi.is_root() ? settling_line.report() : dem::SettlingReport{};
        // A restart replaces every particle state by the checkpoint's (positions, velocities,
        // species, neighbours, contact history, clock, random streams; a dropped realization is
        // never advanced again), so its beds are built but not settled: settling them would only
        // cost minutes on a paper-size bed and be thrown away.
        if (settings->is_steady() && !options.restart.empty())
            throw InputError(SourceLocation{"<command line>", 0},
                             fmt::format("restart = '{}': mode = {} cannot be continued from a "
                                         "checkpoint (a solve keeps "
                                         "micro states in memory that a checkpoint does not hold)",
                                         options.restart, settings->mode_name()));
        const bool skip_settling = check || !options.restart.empty();
        for (int j = 0; j < k; ++j) {
            const long realization = check ? 0 : static_cast<long>(mpi.rank()) * k + j;
            systems.push_back(
                dem::build_system(root, {settings->seed, realization, skip_settling}, settling));
        }
        table->check_all_used(
            [&](const ParamEntry& e) { return dem::unused_key_hint(e, scene.effect_names); });
        // What a new run may not write over (the same check in --check); the root looks.
        if (mpi.is_root()) {
            check_output_is_free(root, *settings, !options.restart.empty());
#if EFDEM_HAVE_HDF5
            if (check && !options.restart.empty())
                check_restart(options.restart, read_checkpoint_header(options.restart),
                              parameter_lines(*table), mpi.size() * settings->realizations_per_rank,
                              settings->checkpoint.allow_physics_change);
#endif
        }
        if (!check) {
            std::filesystem::create_directories(settings->output.directory);
            std::filesystem::create_directories(
                settings->checkpoint.directory);  // a stop signal checkpoints
        }
#if !EFDEM_HAVE_HDF5
        if (settings->checkpoint.enabled() || !options.restart.empty())
            throw InputError(SourceLocation{"<command line>", 0},
                             "checkpoints need HDF5, and this efdem was built without it "
                             "(EFDEM_ENABLE_HDF5=OFF)");
#endif
    } catch (const InputError& e) {
        code = kExitInputError;
        message = e.what();
    } catch (const RuntimeFailure& e) {
        code = kExitRuntimeFailure;
        message = e.what();
    } catch (const std::filesystem::filesystem_error& e) {
        code = kExitInputError;
        message = fmt::format(
            "{} = '{}' cannot be created: {}",
            e.path1() == settings->output.directory ? "output.directory" : "checkpoint.directory",
            quote_for_message(e.path1().string()), e.code().message());
    } catch (const std::exception& e) {
        code = kExitRuntimeFailure;
        message = std::string("unexpected failure during set-up: ") + e.what();
    }
    const Agreement agreed = agree_on_failure(mpi.comm(), code, message);
    // Every rank has built (and settled) its realizations: the set-up's wall time, almost all
    // settling.
    wall.settling_seconds = seconds_since(settling_start);
    if (agreed.exit_code != kExitOk) {
        if (mpi.is_root()) log::error("{}", agreed.message);
        return agreed.exit_code;
    }
    if (!check && settings->output.overwrite && options.restart.empty()) {
        // Replace the earlier run: none of its files may stay mixed with this run's.
        int removal = kExitOk;
        std::string why;
        if (mpi.is_root()) {
            try {
                const auto removed = remove_earlier_run(*settings);
                if (!removed.empty())
                    log::info(
                        "output.overwrite = true: deleted the {} file(s) of the earlier run {}/{}",
                        removed.size(), settings->output.directory.string(),
                        settings->output.prefix);
            } catch (const RuntimeFailure& e) {
                removal = kExitRuntimeFailure;
                why = e.what();
            }
        }
        // Nobody writes before the root has deleted.
        const Agreement removed = agree_on_failure(mpi.comm(), removal, why);
        if (removed.exit_code != kExitOk) {
            if (mpi.is_root()) log::error("{}", removed.message);
            return removed.exit_code;
        }
    }
    if (check) {
        if (mpi.is_root() && list_keys) {
            for (const auto& d : table->declarations())
                std::printf("%s\t%s\t%s\n", d.key.c_str(), d.expected.c_str(),
                            d.required ? "required" : d.fallback.c_str());
        } else if (mpi.is_root()) {
            std::printf("%s", check_report(*table, *settings, systems.front(), ranks).c_str());
        }
        return kExitOk;
    }
    std::optional<RestartData> restart;
    if (!options.restart.empty()) {
        restart.emplace();
        const Agreement loaded = load_restart(mpi.world(), options.restart, parameter_lines(*table),
                                              settings->realizations_per_rank,
                                              settings->checkpoint.allow_physics_change, *restart);
        if (loaded.exit_code != kExitOk) {
            if (mpi.is_root()) log::error("{}", loaded.message);
            return loaded.exit_code;
        }
    }
    return run(mpi, *table, *settings, std::move(systems), restart ? &*restart : nullptr, wall);
}
