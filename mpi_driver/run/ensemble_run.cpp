#include "mpi_driver/run/ensemble_run.hpp"

#include <cmath>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/log.hpp"
#include "mpi_driver/checkpoint/restart_check.hpp"
#include "mpi_driver/ensemble/dem_realization.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"
#include "mpi_driver/ensemble/position_lifter.hpp"
#include "mpi_driver/output/csv_recorder.hpp"
#include "mpi_driver/output/recorder_list.hpp"
#include "mpi_driver/output/thermo_screen.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"
#include "mpi_driver/parallel/mpi_broadcast.hpp"
#include "mpi_driver/run/driver.hpp"
#include "mpi_driver/run/run_advice.hpp"
#include "mpi_driver/run/run_end.hpp"
#include "mpi_driver/run/run_observables.hpp"
#include "mpi_driver/run/run_provenance.hpp"
#include "mpi_driver/run/setup.hpp"
#include "mpi_driver/run/steady_driver.hpp"
#if EFDEM_HAVE_HDF5
#include "mpi_driver/checkpoint/checkpoint_writer.hpp"
#include "mpi_driver/output/hdf5_recorder.hpp"
#endif

namespace efdem::mpi_driver {

namespace {
/// Collective: puts this rank's realizations into the restart's states (a realization dropped
/// after a failure stays as built: it is never advanced again); the stepper's own state is put
/// back by EnsembleStepper::restore_state. A state that does not fit the scene's realizations
/// (another bed) is an input error: exit code 2, with the root's message naming the checkpoint.
Agreement restore_checkpointed_states(MPI_Comm comm, const RestartData& restart,
                                      std::vector<std::unique_ptr<Realization>>& local) {
    int code = kExitOk;
    std::string message;
    try {
        const auto& active = restart.header.stepper.active;
        for (std::size_t j = 0; j < local.size(); ++j) {
            const auto r = static_cast<std::size_t>(local[j]->index());
            // A realization dropped after a failure stays as built: it is never advanced again.
            if (!active.empty() && active[r] == 0) continue;
            local[j]->restore_state(restart.local[j]);
        }
    } catch (const std::exception& e) {
        code = kExitInputError;
        message = fmt::format("{}: checkpoint does not fit the scene: {}", restart.path.string(),
                              e.what());
    }
    return agree_on_failure(comm, code, message);
}
}  // namespace

int run_ensemble(const MpiSession& mpi, const ParamTable& table, const RunSettings& s,
                 std::vector<dem::System> systems, const RestartData* restart,
                 const SetupWall& wall) {
    const std::optional<dem::BedObservationSettings> bed = bed_settings(s, systems.front());
    // The same species and box in every realization: what a lift by positions needs to know.
    const dem::SpeciesTable species = systems.front().species();
    const dem::Domain box = systems.front().domain();
    const bool by_positions = s.lift_by_positions && s.is_cpi();
    const RunProvenance prov = provenance(mpi, table, s, systems.front(), bed);
    if (mpi.is_root())
        for (const std::string& advice :
             run_advice(s.is_cpi(), std::isfinite(s.cpi.jump_until), systems.front()))
            log::warn("{}", advice);
    const EnsembleLayout layout(mpi.world(), s.realizations_per_rank);
    RunObservables observables = RunObservables::from_settings(s);

    std::unique_ptr<RecorderList> recorders;
    std::vector<std::unique_ptr<Realization>> local;
    const bool resume = restart != nullptr;
    std::vector<std::unique_ptr<RunRecorder>> owned;  // until the list takes them
    try {
        if (mpi.is_root()) {
            if (resume) restore_outputs(restart->header, s.output.directory, s.output.prefix);
#if EFDEM_HAVE_HDF5
            owned.push_back(std::make_unique<Hdf5Recorder>(s.output.directory, s.output.prefix,
                                                           prov, observables.primary->dimension(),
                                                           resume));
#endif
            owned.push_back(
                std::make_unique<CsvRecorder>(s.output.directory, s.output.prefix, prov, resume));
            if (s.output.thermo_interval > 0)
                owned.push_back(
                    std::make_unique<ThermoScreen>(s.output.thermo_interval, layout.size()));
            recorders = std::make_unique<RecorderList>(std::move(owned));
        }
        RealizationOutput out{
            s.output.directory, s.output.prefix,
            std::lround(s.output.vtk_interval / s.observe.interval),
            std::lround(s.output.thermo_interval / s.observe.interval),
            resume ? fmt::format("_cont{:08d}", restart->header.stepper.samples_taken) : ""};
        for (auto& sys : systems)
            local.push_back(std::make_unique<DemRealization>(
                std::move(sys), s.observe.species, s.observe.other, out, resume, bed,
                RealizationLift{by_positions, s.carry_species_velocity,
                                s.is_cpi() ? s.relabel_by : coarse::SwitchOrder::By::any}));
    } catch (const std::exception& e) {
        // The run file may exist already (a CSV header on a nearly full disk): it says so.
        RunSummary failed;
        failed.end_status = std::string("failed: ") + e.what();
        try {
            if (recorders) recorders->finish(failed);  // the list holds them all
            for (auto& r : owned) r->finish(failed);   // else those made before the failure
        } catch (const std::exception&) {
        }
        mpi.abort(e.what(), kExitRuntimeFailure);
    }
    if (resume) {
        const Agreement agreed = restore_checkpointed_states(mpi.comm(), *restart, local);
        if (agreed.exit_code != kExitOk) {
            if (mpi.is_root()) log::error("{}", agreed.message);
            return agreed.exit_code;
        }
        log::info("restarted from {} at t = {:.6g}", restart->path.string(), local.front()->time());
    }
    open_run_log(mpi, table, s, restart ? restart->path.string() : std::string());
    // (The header was printed before the beds were built: setup.cpp.)
    log::info("{} particles per realization; the run starts at t = {:.6g}",
              local.front()->particles(), local.front()->time());

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
    ss.hold_at_rest = s.hold_at_rest && s.is_cpi();  // a steady solve lifts every realization
    ss.pause_at_rest = s.pause_at_rest && !s.is_steady();
    // The run's start (progress counts from there; on the non-root ranks it is not used).
    const double t0 =
        resume && mpi.is_root() ? restart->header.driver.t_origin : local.front()->time();
    Progress progress(t0, t0 + s.duration, 2.0);
    const ColourLifter colour_lifter(
        s.is_cpi() ? s.relabel_by : coarse::SwitchOrder::By::any,
        s.relabel_at_nodes ? coarse::Relabel::at_nodes : coarse::Relabel::random);
    dem::OverlapRelaxationSettings relaxation;
    relaxation.height_band = s.lift_height_band;
    const PositionLifter position_lifter(species, s.observe.species, s.observe.other, box,
                                         relaxation, s.lift_resolution);
    const Lifter& lifter =
        by_positions ? static_cast<const Lifter&>(position_lifter) : colour_lifter;
    // A steady solve goes back in time (kept states): its progress is per iterate (steady_driver).
    EnsembleStepper stepper(layout, std::move(local), ss, *observables.primary, lifter,
                            recorders.get(), mpi.is_root() && !s.is_steady() ? &progress : nullptr);
    RunControl control;
    if (resume) {
        stepper.restore_state(restart->header.stepper);
        stepper.resume_wall(restart->header.stepper.wall_seconds);
        control.resume = restart->header.driver;
        // The rate and the time left count this process's work only.
        if (mpi.is_root()) progress.resume(stepper.time(), stepper.particle_steps());
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
    // How the run file is marked when the run fails here: the end status and the counters so
    // far (finish() frees the run file's reserve first). Empty string: every output finished;
    // else what could not be.
    const auto mark_failed = [&](const std::string& why) -> std::string {
        RunSummary failed;
        failed.end_status = "failed: " + why;
        failed.simulated_time = stepper.time() - t0;
        fill_totals(failed, stepper, progress);
        wall.fill(failed);
        try {
            recorders->finish(failed);
        } catch (const std::exception& e) {
            return e.what();
        }
        return {};
    };
    // An abort on the root (a failure the ranks cannot agree on first, e.g. inside a
    // collective checkpoint write) marks the run file too, on its way out.
    MpiComm::set_last_words([&](const std::string& why) { mark_failed(why); });
    struct Silence {
        ~Silence() { MpiComm::set_last_words(nullptr); }
    } silence_at_return;
    RunSummary summary;
    try {
        summary = s.is_steady() ? run_steady(stepper, s, recorders.get(), progress)
                  : s.is_cpi()  ? run_cpi(stepper, s, observables.fallback.get(), recorders.get(),
                                          progress, control)
                                : run_direct(stepper, s, progress, control);
        wall.fill(summary);
        recorders->finish(summary);
    } catch (const RunFailed& e) {
        const std::string unfinished = mark_failed(e.what());
        if (unfinished.empty())
            log::error("the run failed; its files in {} are marked 'failed'",
                       s.output.directory.string());
        else
            log::error(
                "the run failed; not every output file could be finished ({}); the "
                "others are marked 'failed'",
                unfinished);
        return kExitRuntimeFailure;
    } catch (const std::exception& e) {
        // A failure on the root alone (e.g. its run file on a full disk): mark the run file if
        // it can be, then end every rank (the last words would mark it again: silenced).
        mark_failed(e.what());
        MpiComm::set_last_words(nullptr);
        mpi.abort(e.what(), kExitRuntimeFailure);
    }
    return report_end(summary, s, table, mpi.size());
}

}  // namespace efdem::mpi_driver
