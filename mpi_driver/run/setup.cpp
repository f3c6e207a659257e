#include "mpi_driver/run/setup.hpp"

#include <exception>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/version.hpp"
#include "dem/io/lammps_data.hpp"
#include "dem/realization_builder.hpp"
#include "dem/scene.hpp"
#include "mpi_driver/checkpoint/restart_check.hpp"
#include "mpi_driver/parallel/scene_input.hpp"
#include "mpi_driver/parallel/stop_signal.hpp"
#include "mpi_driver/run/ensemble_size.hpp"
#include "mpi_driver/run/output_guard.hpp"
#include "mpi_driver/run/settling_progress.hpp"
#if EFDEM_HAVE_HDF5
#include "mpi_driver/checkpoint/checkpoint_reader.hpp"
#endif

namespace efdem::mpi_driver {

namespace {

/// A stop signal while the beds are being settled: before the run exists there is nothing to
/// checkpoint, so set-up ends at once (at the next half time unit of settling) with exit 4.
class SettlingStopped : public std::runtime_error {
  public:
    SettlingStopped(int signal, const dem::SettlingProgress& p)
        : std::runtime_error(fmt::format(
              "stopped by {} during set-up, while settling realization {} ({} stage, t = {:.4g}): "
              "the run had not started, so there is nothing to checkpoint; run the same command "
              "again to start it",
              signal_name(signal), p.realization, dem::to_string(p.stage), p.time)) {}
};

/// Every rank: reads the scene and builds its beds; throws what a bad scene or a failing build
/// throws (the caller turns it into the agreement).
void read_and_build(const MpiSession& mpi, const RunOptions& options, SetUp& out) {
    out.table.emplace(read_scene(mpi, options.scene, options.overrides));
    Params root = out.table->root();
    const dem::DemScene scene = dem::DemScene::from_params(root);
    out.settings = RunSettings::from_params(root, scene);
    RunSettings& settings = *out.settings;
    settings.check_ensemble(root, out.ranks * settings.realizations_per_rank);
    const int k = out.check ? 1 : settings.realizations_per_rank;
    // Settling a paper-size bed takes minutes: the root says how its own realizations go (the
    // other ranks settle theirs at the same time).
    SettlingProgressLine settling_line(5.0);
    // Every rank looks for a stop signal after each half time unit of settling.
    const dem::SettlingReport settling =
        [line = mpi.is_root() ? settling_line.report()
                              : dem::SettlingReport{}](const dem::SettlingProgress& p) {
            if (line) line(p);
            if (const int signal = stop_signal_received(); signal != 0)
                throw SettlingStopped(signal, p);
        };
    // A restart replaces every particle state by the checkpoint's (positions, velocities,
    // species, neighbours, contact history, clock, random streams; a dropped realization is
    // never advanced again), so its beds are built but not settled: settling them would only
    // cost minutes on a paper-size bed and be thrown away.
    if (settings.is_steady() && !options.restart.empty())
        throw InputError(SourceLocation{"<command line>", 0},
                         fmt::format("restart = '{}': mode = {} cannot be continued from a "
                                     "checkpoint (a solve keeps "
                                     "micro states in memory that a checkpoint does not hold)",
                                     options.restart, settings.mode_name()));
    const bool skip_settling = out.check || !options.restart.empty();
    // bed.write: each rank keeps its beds as built, and writes them once the output guard has
    // passed (set_up, write_beds); a restart's beds (overwritten by its checkpoint) are not.
    const bool keep_beds =
        !out.check && options.restart.empty() && !settings.output.bed_write.empty();
    // The run's header before the beds are built: settling a large bed takes minutes, and the
    // user should see at once what runs where.
    if (!out.check && mpi.is_root())
        log::info("efdem {}: {} run of {} on {}, output {}/{}.*{}", version(), settings.mode_name(),
                  out.table->file(), ensemble_size(mpi.size(), settings.realizations_per_rank),
                  settings.output.directory.string(), settings.output.prefix,
                  options.restart.empty() ? "" : fmt::format("; continuing {}", options.restart));
    for (int j = 0; j < k; ++j) {
        const long realization = out.check ? 0 : static_cast<long>(mpi.rank()) * k + j;
        out.systems.push_back(dem::build_system(
            root, {settings.seed, realization, skip_settling, !options.restart.empty()}, settling,
            keep_beds ? &out.beds.emplace_back() : nullptr));
    }
    // --check builds realization 0 only: the other realizations' kept beds must be there too.
    if (out.check && options.restart.empty()) {
        const dem::BedSpec bed = dem::BedSpec::from_params(root.scope("bed"), scene);
        for (long r = 1; r < static_cast<long>(out.ranks) * settings.realizations_per_rank; ++r)
            dem::check_kept_bed_exists(bed, root.scope("bed"), r);
    }
    out.table->check_all_used(
        [&](const ParamEntry& e) { return dem::unused_key_hint(e, scene.effect_names); });
    // What a new run may not write over (the same check in --check); the root looks.
    if (mpi.is_root()) {
        check_output_is_writable(root, settings);
        // One run at a time under a prefix: the lock is taken before the output is looked at,
        // so that no other run can create files between the look and this run's writing.
        if (out.check) {
            OutputLock::check_free(root, settings.output.directory, settings.output.prefix);
        } else {
            std::filesystem::create_directories(settings.output.directory);
            out.lock.emplace(root, settings.output.directory, settings.output.prefix);
        }
        check_output_is_free(root, settings, !options.restart.empty());
        check_bed_write_is_free(root, settings,
                                static_cast<long>(out.ranks) * settings.realizations_per_rank,
                                !options.restart.empty());
#if EFDEM_HAVE_HDF5
        if (!options.restart.empty()) {
            // Read once here. A checkpoint that cannot be read: --check says why now; a run
            // leaves it to load_restart, which says the same collectively.
            std::optional<CheckpointHeader> header;
            try {
                header = read_checkpoint_header(options.restart);
            } catch (const std::exception&) {
                if (out.check) throw;
            }
            if (header) check_restart_target(root, settings, options.restart, *header);
            if (header && out.check)
                check_restart(options.restart, *header, parameter_lines(*out.table),
                              mpi.size() * settings.realizations_per_rank,
                              settings.checkpoint.allow_physics_change,
                              read_checkpoint_time(options.restart));
        }
#endif
    }
    if (!out.check) {
        std::filesystem::create_directories(settings.output.directory);
        std::filesystem::create_directories(
            settings.checkpoint.directory);  // a stop signal checkpoints
    }
#if !EFDEM_HAVE_HDF5
    if (settings.checkpoint.enabled() || !options.restart.empty())
        throw InputError(SourceLocation{"<command line>", 0},
                         "checkpoints need HDF5, and this efdem was built without it "
                         "(EFDEM_ENABLE_HDF5=OFF)");
#endif
}

/// output.overwrite = true (not a restart): the root deletes the earlier run's files, so that
/// none stays mixed with this run's; nobody writes before it has. Collective.
Agreement replace_earlier_run(const MpiSession& mpi, const RunSettings& settings) {
    int removal = kExitOk;
    std::string why;
    if (mpi.is_root()) {
        try {
            const auto removed = remove_earlier_run(settings);
            if (!removed.empty())
                log::info(
                    "output.overwrite = true: deleted the {} file(s) of the earlier run {}/{}",
                    removed.size(), settings.output.directory.string(), settings.output.prefix);
        } catch (const RuntimeFailure& e) {
            removal = kExitRuntimeFailure;
            why = e.what();
        }
    }
    return agree_on_failure(mpi.comm(), removal, why);
}

/// bed.write: every rank writes its realizations' beds as built (and settled), one LAMMPS data
/// file each, and drops its copies. Collective; a file that cannot be written ends the set-up
/// (exit 3), naming it.
Agreement write_beds(const MpiSession& mpi, const RunSettings& settings, SetUp& out) {
    int code = kExitOk;
    std::string why;
    const int k = settings.realizations_per_rank;
    try {
        for (std::size_t j = 0; j < out.beds.size(); ++j) {
            const long r = static_cast<long>(mpi.rank()) * k + static_cast<long>(j);
            dem::write_lammps_data(
                dem::realization_file(settings.output.bed_write, r), out.beds[j],
                out.systems[j].species(), out.systems[j].domain(),
                fmt::format("efdem {} bed of realization {}, seed {}, scene {} (bed.write; "
                            "LAMMPS atom_style sphere)",
                            version(), r, settings.seed, out.table->file()));
        }
    } catch (const RuntimeFailure& e) {
        code = kExitRuntimeFailure;
        why = e.what();
    }
    out.beds.clear();
    const Agreement agreed = agree_on_failure(mpi.comm(), code, why);
    const long realizations = static_cast<long>(mpi.size()) * k;
    if (agreed.exit_code == kExitOk && mpi.is_root())
        log::info("bed.write: the beds of the {} realization(s) are in {}{}", realizations,
                  dem::realization_file(settings.output.bed_write, 0).string(),
                  realizations > 1
                      ? fmt::format(" .. {}", dem::realization_file(settings.output.bed_write,
                                                                    realizations - 1)
                                                  .filename()
                                                  .string())
                      : std::string());
    return agreed;
}

}  // namespace

Agreement set_up(const MpiSession& mpi, const RunOptions& options, SetupWall& wall, SetUp& out) {
    out.check = options.action == RunOptions::Action::check ||
                options.action == RunOptions::Action::list_keys;
    out.ranks = options.ranks > 0 ? options.ranks : mpi.size();
    int code = kExitOk;
    std::string message;
    const SetupWall::Clock::time_point settling_start = SetupWall::Clock::now();
    try {
        read_and_build(mpi, options, out);
    } catch (const SettlingStopped& e) {
        code = kExitInterrupted;
        message = e.what();
    } catch (const InputError& e) {
        code = kExitInputError;
        message = e.what();
    } catch (const RuntimeFailure& e) {
        code = kExitRuntimeFailure;
        message = e.what();
    } catch (const std::filesystem::filesystem_error& e) {
        code = kExitInputError;
        message = fmt::format("{} = '{}' cannot be created: {}",
                              e.path1() == out.settings->output.directory ? "output.directory"
                                                                          : "checkpoint.directory",
                              quote_for_message(e.path1().string()), e.code().message());
    } catch (const std::exception& e) {
        code = kExitRuntimeFailure;
        message = std::string("unexpected failure during set-up: ") + e.what();
    }
    const Agreement agreed = agree_on_failure(mpi.comm(), code, message);
    // Every rank has built (and settled) its realizations: the set-up's wall time, almost all
    // settling.
    wall.settling_seconds = SetupWall::seconds_since(settling_start);
    if (agreed.exit_code != kExitOk) return agreed;
    Agreement done = agreed;
    if (!out.check && out.settings->output.overwrite && options.restart.empty())
        done = replace_earlier_run(mpi, *out.settings);
    if (done.exit_code == kExitOk && !out.check && options.restart.empty() &&
        !out.settings->output.bed_write.empty())
        done = write_beds(mpi, *out.settings, out);
    return done;
}

/// Root: PREFIX_log.txt from here on, once the output guard has passed (it counts the log as a
/// file of its run, so an earlier run's is never in the way): the scene as read, then
/// everything printed so far and from now on; a restart appends to its run's log. Not
/// PREFIX.log: that is where batch scripts send a job's output (`mpirun efdem ... >
/// PREFIX.log`, under mpirun a pipe, so the two could not be told apart and would interleave).
void open_run_log(const MpiSession& mpi, const ParamTable& table, const RunSettings& settings,
                  const std::string& restart) {
    if (!mpi.is_root()) return;
    const std::filesystem::path path =
        settings.output.directory / (settings.output.prefix + "_log.txt");
    std::string preamble;
    if (!restart.empty())
        preamble += fmt::format("----- restart={}: the run continues -----\n", restart);
    preamble += fmt::format("----- scene {}, as read -----\n{}", table.file(), table.text());
    if (!preamble.ends_with('\n')) preamble += '\n';
    preamble += fmt::format("----- command-line overrides: {} -----\n",
                            table.overrides().empty()
                                ? std::string("none")
                                : fmt::format("{}", fmt::join(table.overrides(), " ")));
    const bool replace = settings.output.overwrite && restart.empty();
    if (const std::string why = log::open_copy(path, replace, preamble); !why.empty())
        log::warn("no log file: {}; the run goes on, printing to the screen only", why);
}

}  // namespace efdem::mpi_driver
