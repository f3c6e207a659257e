#pragma once
/// \file
/// EnsembleStepper: the coarse time-stepper of an MPI ensemble (coarse::CoarseStepper), in the
/// shape of the product's design:
///
///   run(duration):  every rank advances its realizations; at each sampling interval the root
///                   gathers each realization's ICDF (and centre-of-mass height), averages
///                   them in realization order, records the sample and appends the coarse
///                   vector to the burst;
///   lift(X, t):     the root gathers what lifting needs from each realization (a DEM
///                   realization: particle heights and colours), computes each one's lifted
///                   state with the Lifter and that realization's `lifting` random stream, and
///                   scatters it (MPI_Scatterv); every rank applies it and sets its clock to t.
///                   With lift_members (cpi.lift = members) the target of realization r is its
///                   own X_r + (X - mean_r X_r), one more gather of the realizations' ICDFs.
///
/// Only the root runs the macro integrator. The root's run()/lift() first broadcast a command;
/// the other ranks sit in serve(), which executes the same collectives, until finish().
/// After every sample's DEM steps (and again after its per-realization output) the ranks agree
/// (one MPI_Allreduce) on two things:
///
/// * a failure (e.g. a blown-up realization: the watchdog of dem::System, a full disk): the
///   failing rank prints it with the rank and realization named and where the last checkpoint
///   is; every rank throws RunFailed, the root marks the run file, and all exit together (no
///   rank waits in a collective, nobody calls MPI_Abort);
/// * a stop signal (stop_signal.hpp) received by any rank: every rank stops after that sample
///   (interrupted()); the root's run() throws RunInterrupted if the burst was cut short.
///
/// Resume points (cpi): mark_resume_point() keeps every realization's state and the loop's state
/// in memory between coarse steps and holds the samples taken after it back from the recorder
/// until the next mark; checkpoint_resume_point() writes that state as a checkpoint. So a stop
/// in the middle of a coarse step is checkpointed where the step began, and the restarted run
/// redoes the step exactly as the uninterrupted run did it.

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "coarse/demixing/ensemble_observable.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "coarse/equation_free/coarse_stepper.hpp"
#include "core/rng.hpp"
#include "dem/beds/bed_observation.hpp"
#include "mpi_driver/checkpoint/checkpoint_format.hpp"
#include "mpi_driver/ensemble/ensemble_layout.hpp"
#include "mpi_driver/ensemble/failure_policy.hpp"
#include "mpi_driver/ensemble/injected_failure.hpp"
#include "mpi_driver/ensemble/realization.hpp"
#include "mpi_driver/output/progress.hpp"
#include "mpi_driver/output/run_recorder.hpp"

namespace efdem::mpi_driver {

struct StepperSettings {
    double sample_interval = 0.5;  ///< time between samples [sqrt(d_p/g)]
    long steps_per_sample = 1;     ///< micro steps per sample
    int quantiles = 19;            ///< m of the p-grid
    std::uint64_t seed = 1;        ///< master seed (for the lifting streams)
    InjectedFailure failure;
    FailurePolicy on_failure;  ///< what a realization's failure does (abort, drop, replace)
    /// Root: an observable evaluated at every sample only to be recorded (e.g. the compact
    /// (A,B,C,D) of a direct run, for comparison with a compact CPI run); null for none.
    coarse::EnsembleObservable* recorded = nullptr;
    /// mode = continuation: the scene key set_parameter() changes (continuation_parameters()).
    std::string parameter;
    /// observe.bed: how the realizations measure the bed (their Observation::bed); none: not
    /// gathered.
    std::optional<dem::BedObservationSettings> bed;
    /// cpi.lift = members: lift(X) moves every realization by the same increment, to its own
    /// X_r + (X - mean_r X_r), so that each keeps its offset from the ensemble mean (the spread of
    /// a direct ensemble) instead of all collapsing onto X. Needs an observable that restricts
    /// members (the ICDF). A realization rebuilt after a failure is still lifted to X itself.
    bool lift_members = false;
};

class EnsembleStepper final : public coarse::CoarseStepper {
  public:
    /// `local`: this rank's k realizations; `observable`, `lifter` and `recorder` are used on
    /// the root only (recorder and progress may be null).
    EnsembleStepper(const EnsembleLayout& layout, std::vector<std::unique_ptr<Realization>> local,
                    const StepperSettings& settings, coarse::EnsembleObservable& observable,
                    const Lifter& lifter, RunRecorder* recorder, Progress* progress);

    double time() const override;
    int realizations() const { return layout_.size(); }
    void run(double duration, coarse::BurstSamples& out) override;
    void lift(const Eigen::VectorXd& target, double new_time) override;
    /// Every rank keeps its realizations' states in memory (RealizationState, as a checkpoint
    /// does), the root its lifting streams and warm starts; samples are held back from the
    /// recorder until confirm_kept_state() and dropped by return_to_kept_state(). The cost
    /// counters (micro_time(), particle_steps()) keep counting the work that was discarded.
    /// Per-realization VTK and thermo output of a discarded burst stays written.
    bool can_keep_state() const override { return true; }
    void keep_state() override;
    void return_to_kept_state() override;
    void confirm_kept_state() override;
    /// Root: sets StepperSettings::parameter to `value` on every realization (every rank joins
    /// through serve()): the continuation parameter, before a lift. Not part of the kept state.
    void set_parameter(double value);

    /// Root: write a whole-ensemble checkpoint numbered `sequence` with the driver's state
    /// (every rank joins through serve()). Needs set_checkpoint_writer(). Returns its path.
    std::filesystem::path checkpoint(long sequence, const DriverState& driver);
    /// Every rank: the writer used by checkpoint() (null: none).
    /// `periodic`: the run also checkpoints at intervals (else only where a signal stops it).
    void set_checkpoint_writer(const CheckpointSink* writer, bool periodic = true) {
        writer_ = writer;
        periodic_checkpoints_ = periodic;
    }
    bool can_checkpoint() const { return writer_ != nullptr; }
    /// The coarse layer's state (root: all of it; elsewhere the counters), and its restoration
    /// on a restart (every rank; the lifting streams and warm starts matter on the root only).
    StepperState saved_state() const;
    void restore_state(const StepperState& state);
    long samples_taken() const { return samples_taken_; }

    /// Non-root ranks: execute the root's commands until finish(). Collective.
    void serve();
    /// Root: release the other ranks from serve() with the run's exit code (finish_code()).
    /// Samples held back since the last resume point are recorded first, unless the run was
    /// interrupted (the checkpoint continues it).
    void finish(int exit_code = 0);
    /// Non-root ranks, after serve(): the exit code the root finished with.
    int finish_code() const { return finish_code_; }

    /// Every rank: the stop signal the ensemble agreed on (0: none yet).
    int interrupted() const { return interrupted_; }
    /// Realizations in the ensemble (R less those dropped), and failures survived so far.
    int active_realizations() const;
    long failures() const { return failures_; }
    /// Root, after run() threw EnsembleChanged (cpi: a realization failed and is dropped or
    /// replaced): every realization goes back to the resume point, the failed ones leave the
    /// ensemble or are rebuilt there from a healthy one (fresh lifting stream, lifted to the
    /// ensemble's coarse state at the resume point), and the failures are recorded. The loop
    /// then continues from resume_driver(). Collective through serve().
    void rebuild_after_failure();
    const DriverState& resume_driver() const { return resume_driver_; }
    /// Root: keep the state here (every realization, the stepper, the loop's `driver` state) as
    /// the point a stop is checkpointed at, and record the samples held back since the last
    /// one. Call only where nothing of a burst is pending (between coarse steps).
    void mark_resume_point(const DriverState& driver);
    bool has_resume_point() const { return has_resume_point_; }
    /// Root: write the kept resume point as checkpoint number driver.coarse_steps (every rank
    /// joins through serve()). Needs set_checkpoint_writer(). Returns its path.
    std::filesystem::path checkpoint_resume_point();
    double resume_point_time() const { return resume_time_; }

    /// Root: what the last lift did per realization, and the last sample.
    const LiftRecord& last_lift() const { return last_lift_; }
    const SampleRecord& last_sample() const { return last_sample_; }
    /// Particle-steps done by the whole ensemble so far.
    double particle_steps() const { return particle_steps_; }
    /// Micro time simulated per realization so far.
    double micro_time() const { return micro_time_; }
    /// Root: lowest and highest particle centre over the ensemble at the last sample [d_p]:
    /// the feasible range of a lifting target.
    std::pair<double, double> height_range() const { return height_range_; }
    void set_observable(coarse::EnsembleObservable& observable) { observable_ = &observable; }
    /// Root, with lift_members: makes each realization's own target liftable (the observable's
    /// repair hook, as the integrator applies to the mean target); none: targets as computed.
    void set_member_repair(coarse::RepairHook repair) { member_repair_ = std::move(repair); }
    /// Root: the coarse observable in use (its status_message() says why a sample failed).
    const coarse::EnsembleObservable& observable() const { return *observable_; }
    coarse::EnsembleObservable& observable() { return *observable_; }
    /// Root: whether samples need the top-half ICDF (for the integrator's or the recorded
    /// observable).
    bool needs_top_half() const;

    /// Wall time spent in the ensemble-level work of the coarse loop (not in the DEM), summed
    /// so far [s]: restriction (observe, gather, average, record) and lifting (gather heights
    /// and colours, compute every lift on the root, scatter, apply).
    struct Overhead {
        double restrict_seconds = 0;
        double lift_seconds = 0;
        long samples = 0;
        long lifts = 0;
    };
    const Overhead& overhead() const { return overhead_; }
    std::vector<std::unique_ptr<Realization>>& local() { return local_; }

  private:
    enum class Command : int {
        run = 1,
        lift = 2,
        finish = 3,
        checkpoint = 4,
        keep = 5,
        go_back = 6,
        confirm = 7,
        mark = 8,
        checkpoint_mark = 9,
        rebuild = 10,
        set_parameter = 11,
        lift_members = 12  ///< a lift that moves each realization by the same increment
    };
    /// The root's command, its argument, and whether the top-half ICDF is gathered (the
    /// observable lives on the root only and may change during a run: the workers must join
    /// exactly the collectives the root joins).
    struct Message {
        Command command;
        double value;
        bool top_half;
    };
    Message broadcast(Message m) const;
    /// Returns the samples taken (fewer than `samples` when a stop was agreed).
    long do_run(long samples, bool top_half, coarse::BurstSamples* out);
    /// A local realization's failure: its global index and the message.
    struct Failure {
        long realization;
        std::string message;
    };
    /// Collective: agree on failures (any: RunFailed on every rank) and, with `with_signal`,
    /// on a stop signal (returned; 0: none).
    int agree(const std::vector<Failure>& failures, bool with_signal);
    [[noreturn]] void fail_agreed(const std::vector<Failure>& failures);
    std::string where_saved() const;
    /// Root: to the recorder, or held back (provisional, or after a resume point).
    void record(const SampleRecord& s);
    void do_mark();
    void flush_since_mark();
    /// `only` (every rank; null: all): lift just the realizations marked 1.
    /// `members`: each realization to its own X_r + (target - mean X_r) (the root decides, the
    /// workers are told by the command: it adds a gather).
    void do_lift(double new_time, bool top_half, const Eigen::VectorXd* target, bool members,
                 const std::vector<char>* only = nullptr);
    bool is_active(const Realization& r) const {
        return active_[static_cast<std::size_t>(r.index())] != 0;
    }
    void on_failures(const std::vector<Failure>& failures);
    /// Root: every realization's failure message (empty where none); collective.
    std::vector<std::string> gather_failure_messages(const std::vector<Failure>& failures) const;
    void do_rebuild(bool top_half);
    void send_states(const std::vector<long>& failed, const std::vector<long>& donors);
    void take_sample(bool top_half, coarse::BurstSamples* out);
    std::filesystem::path do_checkpoint(long sequence, const CheckpointHeader* header,
                                        bool at_resume_point);
    [[noreturn]] void fail(const std::string& message, long realization) const;
    void do_keep();
    /// This rank's realizations' states; a failure (`when`: for the message) ends the job.
    std::vector<RealizationState> saved_realizations(const char* when) const;
    void do_go_back();
    void do_confirm();
    void do_set_parameter(double value);

    const EnsembleLayout& layout_;
    std::vector<std::unique_ptr<Realization>> local_;
    StepperSettings settings_;
    coarse::EnsembleObservable* observable_;
    const Lifter& lifter_;
    RunRecorder* recorder_;
    Progress* progress_;
    const CheckpointSink* writer_ = nullptr;
    bool periodic_checkpoints_ = false;
    std::filesystem::path last_checkpoint_;  ///< every rank: the newest checkpoint written
    double last_checkpoint_time_ = 0;
    coarse::ProbabilityGrid grid_;
    std::vector<RandomStream> lifting_;  ///< root: one lifting stream per realization
    long samples_taken_ = 0;
    double particle_steps_ = 0;
    double micro_time_ = 0;
    double total_particles_ = 0;
    std::pair<double, double> height_range_{0.0, 0.0};
    LiftRecord last_lift_;
    coarse::RepairHook member_repair_;
    SampleRecord last_sample_;
    Overhead overhead_;
    bool provisional_ = false;            ///< between keep_state() and its end
    std::vector<RealizationState> kept_;  ///< every rank: its realizations' kept states
    StepperState kept_stepper_;
    SampleRecord kept_sample_;
    std::vector<SampleRecord> pending_;  ///< root: samples since keep_state()
    int interrupted_ = 0;                ///< every rank: the agreed stop signal
    int finish_code_ = 0;
    bool has_resume_point_ = false;
    std::vector<RealizationState> resume_states_;  ///< every rank: at the resume point
    StepperState resume_stepper_;  ///< every rank (lifting streams, warm starts: root)
    DriverState resume_driver_;    ///< root
    double resume_time_ = 0;
    std::vector<SampleRecord> since_mark_;  ///< root: confirmed samples after the resume point
    SampleRecord resume_sample_;            ///< root: the last sample at the resume point
    Eigen::VectorXd last_x_,
        resume_x_;  ///< root: the last restricted coarse vector, and at the resume point
    std::vector<char> active_;          ///< every rank: per realization, in the ensemble
    long failures_ = 0;                 ///< every rank: failures survived
    bool injected_fired_ = false;       ///< the injected failure happens once
    bool changed_ = false;              ///< every rank: failures await rebuild_after_failure()
    std::vector<long> failed_pending_;  ///< every rank: which
    std::vector<std::string> failed_reasons_;  ///< root: why (per realization)
    double failed_time_ = 0;
};

/// Thrown on the root by EnsembleStepper::run() in cpi when realizations failed and are to be
/// dropped or replaced: the driver calls rebuild_after_failure() and continues the loop from
/// the resume point.
class EnsembleChanged : public std::runtime_error {
  public:
    EnsembleChanged()
        : std::runtime_error("realizations failed; the coarse step is redone without them") {}
};

/// Every rank, when the ensemble agreed that a realization failed (its rank printed why).
class RunFailed : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

}  // namespace efdem::mpi_driver
