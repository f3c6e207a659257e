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
/// The stepper is that face and the command loop; four parts do the work, one job each:
///
///   EnsembleSampler    restriction: observe, gather in realization order, mean and variance,
///                      the sample record and the coarse vector (ensemble_sampler.hpp);
///   EnsembleLifting    lifting: mean or members targets, the per-realization lifting streams,
///                      gather, lift on the root, scatter, apply (ensemble_lifting.hpp);
///   EnsembleSnapshots  the kept state (reject-and-redo) and the resume point (stops and
///                      failures): one snapshot type, which state is valid on which rank, and
///                      the samples held back until they can no longer be taken back
///                      (ensemble_snapshots.hpp);
///   FailureAgreement   after every sample, the ranks agree (one MPI_Allreduce) on failures and
///                      stop signals; drop, rebuild from a donor (failure_agreement.hpp).
///
/// A failure ends the run on every rank together (RunFailed) or changes the ensemble
/// (failure_policy.hpp); a stop signal agreed after a sample ends run() there (interrupted();
/// the root's run() throws RunInterrupted if the burst was cut short). Samples and survived
/// failures leave the ensemble through a SampleSink (output/sample_sink.hpp), on the root.
///
/// Resume points (cpi): mark_resume_point() keeps every realization's state and the loop's state
/// in memory between coarse steps and holds the samples taken after it back from the sink
/// until the next one; checkpoint_resume_point() writes that state as a checkpoint. So a stop
/// in the middle of a coarse step is checkpointed where the step began, and the restarted run
/// redoes the step exactly as the uninterrupted run did it.

#include <cmath>
#include <limits>
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
#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/ensemble/ensemble_lifting.hpp"
#include "mpi_driver/ensemble/ensemble_sampler.hpp"
#include "mpi_driver/ensemble/ensemble_snapshots.hpp"
#include "mpi_driver/ensemble/failure_agreement.hpp"
#include "mpi_driver/ensemble/failure_policy.hpp"
#include "mpi_driver/ensemble/injected_failure.hpp"
#include "mpi_driver/ensemble/realization.hpp"
#include "mpi_driver/output/progress.hpp"
#include "mpi_driver/output/sample_sink.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"

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
    /// mode = continuation: the scene key set_parameter() changes (one of dem::run_parameters()).
    std::string parameter;
    /// observe.bed: how the realizations measure the bed (their Observation::bed); none: not
    /// gathered.
    std::optional<dem::BedObservationSettings> bed;
    /// cpi.lift = members: lift(X) moves every realization by the same increment, to its own
    /// X_r + (X - mean_r X_r), so that each keeps its offset from the ensemble mean (the spread of
    /// a direct ensemble) instead of all collapsing onto X. Needs an observable that restricts
    /// members (the ICDF). A realization rebuilt after a failure is still lifted to X itself.
    bool lift_members = false;
    /// cpi.at_rest = hold: a lift leaves every realization at rest (Realization::at_rest) where
    /// it is and moves the others by the ensemble's whole increment (EnsembleLifting). Needs an
    /// observable that restricts members; with one that does not, every realization is lifted.
    bool hold_at_rest = false;
    /// ensemble.at_rest = pause: a realization at rest (Realization::at_rest) is not advanced;
    /// its clock keeps time (a bed at rest stays so: its state would change by floating-point
    /// drift alone). Its particle-steps are not counted.
    bool pause_at_rest = false;
};

class EnsembleStepper final : public coarse::CoarseStepper {
  public:
    /// `local`: this rank's k realizations; `observable`, `lifter` and `sink` are used on the
    /// root only (sink and progress may be null).
    EnsembleStepper(const EnsembleLayout& layout, Realizations local,
                    const StepperSettings& settings, coarse::EnsembleObservable& observable,
                    const Lifter& lifter, SampleSink* sink, Progress* progress);

    double time() const override;
    int realizations() const { return layout_.size(); }
    void run(double duration, coarse::BurstSamples& out) override;
    void lift(const Eigen::VectorXd& target, double new_time) override;
    /// cpi.lift = own: lift_members's lift, each realization moved by its row of member_steps
    /// on top (EnsembleLifting). Root only, like lift().
    bool lifts_apart() const override;
    void lift_apart(const Eigen::VectorXd& target, const Eigen::MatrixXd& member_steps,
                    double new_time) override;
    /// Every rank keeps its realizations' states in memory (an EnsembleSnapshot: RealizationState,
    /// as a checkpoint does), the root its lifting streams and warm starts; samples are held back
    /// from the sink until confirm_kept_state() and dropped by return_to_kept_state(). The cost
    /// counters (micro_time(), particle_steps()) keep counting the work that was discarded.
    /// Per-realization VTK and thermo output of a discarded burst stays written.
    bool can_keep_state() const override { return true; }
    void keep_state() override;
    void return_to_kept_state() override;
    void confirm_kept_state() override;
    /// Root, where a cpi run hands its state to a steady solve (cpi.hand_off = steady): from
    /// now on every lift puts every realization on its target (Phi_tau lifts one X, so
    /// cpi.lift = members | own and cpi.at_rest = hold no longer apply), and no progress line is
    /// drawn (a solve goes back in time; it logs each iterate instead).
    void begin_steady_solve();
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
    /// Wall seconds the newest checkpoint took to write (every rank: each measures its own).
    double last_checkpoint_seconds() const { return last_checkpoint_seconds_; }
    /// The coarse layer's state (root: all of it; elsewhere the counters), and its restoration
    /// on a restart (every rank; the lifting streams and warm starts matter on the root only).
    StepperState saved_state() const;
    void restore_state(const StepperState& state);
    /// Root, a restarted run: the run loop's wall time of the processes before this one, up to
    /// the checkpoint it resumed (StepperState::wall_seconds; NaN: unknown). saved_state() adds
    /// this process's (from the progress clock; NaN without one, as in a steady solve).
    void resume_wall(double seconds) { wall_before_ = seconds; }
    double wall_before() const { return wall_before_; }
    long samples_taken() const { return samples_taken_; }
    /// Root: the first sample from which every realization in the ensemble has been at rest
    /// (Realization::at_rest), up to the last; NaN when one moves (or none is left).
    double end_state_since() const override { return at_rest_since_; }
    /// Root: some realization in the ensemble was at rest at the last sample.
    bool any_at_rest() const override { return any_at_rest_; }

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
    int active_realizations() const { return failures_.active_count(); }
    long failures() const { return failures_.failures(); }
    /// Root, after run() threw EnsembleChanged (cpi: a realization failed and is dropped or
    /// replaced): every realization goes back to the resume point, the failed ones leave the
    /// ensemble or are rebuilt there from a healthy one (fresh lifting stream, lifted to the
    /// ensemble's coarse state at the resume point), and the failures are recorded. The loop
    /// then continues from resume_driver(). Collective through serve().
    void rebuild_after_failure();
    const DriverState& resume_driver() const {
        return snapshots_.get(EnsembleSnapshots::Use::resume).driver;
    }
    /// Root: keep the state here (every realization, the stepper, the loop's `driver` state) as
    /// the point a stop is checkpointed at, and record the samples held back since the last
    /// one. Call only where nothing of a burst is pending (between coarse steps).
    void mark_resume_point(const DriverState& driver);
    bool has_resume_point() const { return snapshots_.has(EnsembleSnapshots::Use::resume); }
    /// Root: write the kept resume point as checkpoint number driver.coarse_steps (every rank
    /// joins through serve()). Needs set_checkpoint_writer(). Returns its path.
    std::filesystem::path checkpoint_resume_point();
    double resume_point_time() const {
        return has_resume_point() ? snapshots_.get(EnsembleSnapshots::Use::resume).time : 0.0;
    }

    /// Root: what the last lift did per realization, and the last sample.
    const LiftRecord& last_lift() const { return lifting_.last(); }
    /// Root: coarse::CoarseStepper::lift_failure, from the last lift.
    std::string lift_failure() const override { return lifting_.last_failure(); }
    /// Root: coarse::CoarseStepper::lift_error, LiftRecord::error of the last lift (0 if none).
    double lift_error() const override {
        return std::isfinite(lifting_.last().error) ? lifting_.last().error : 0.0;
    }
    const SampleRecord& last_sample() const { return sampler_.last(); }
    /// Particle-steps done by the whole ensemble so far.
    double particle_steps() const { return particle_steps_; }
    /// Micro time simulated per realization so far.
    double micro_time() const { return micro_time_; }
    /// Root: lowest and highest particle centre over the ensemble at the last sample [d_p]:
    /// the feasible range of a lifting target.
    std::pair<double, double> height_range() const { return sampler_.height_range(); }
    void set_observable(coarse::EnsembleObservable& observable) {
        sampler_.set_observable(observable);
    }
    /// Root, with lift_members: makes each realization's own target liftable (the observable's
    /// repair hook, as the integrator applies to the mean target); none: targets as computed.
    void set_member_repair(coarse::RepairHook repair) {
        lifting_.set_member_repair(std::move(repair));
    }
    /// Root: the coarse observable in use (its status_message() says why a sample failed).
    const coarse::EnsembleObservable& observable() const { return sampler_.observable(); }
    coarse::EnsembleObservable& observable() { return sampler_.observable(); }
    /// Root: the reference ICDFs samples need (for the integrator's and the recorded
    /// observable).
    ReferenceNeeds needs() const { return sampler_.needs(); }

    /// Wall time spent in the ensemble-level work of the coarse loop (not in the DEM), summed
    /// so far [s]: restriction (observe, gather, average, record) and lifting (gather heights
    /// and colours, compute every lift on the root, scatter, apply).
    struct Overhead {
        double restrict_seconds = 0;
        double lift_seconds = 0;
        long samples = 0;
        long lifts = 0;
    };
    Overhead overhead() const {
        return {sampler_.seconds() + record_seconds_, lifting_.seconds(), sampler_.count(),
                lifting_.count()};
    }

  private:
    enum class Command : int {
        run = 1,
        lift = 2,
        finish = 3,
        checkpoint = 4,
        keep = 5,
        go_back = 6,
        confirm = 7,
        resume_point = 8,
        checkpoint_resume_point = 9,
        rebuild = 10,
        set_parameter = 11,
        lift_members = 12  ///< a lift that moves each realization by the same increment
    };
    /// The root's command, its argument, and which reference ICDFs are gathered (the
    /// observable lives on the root only and may change during a run: the workers must join
    /// exactly the collectives the root joins).
    struct Message {
        Command command;
        double value;
        ReferenceNeeds needs;
        bool hold_at_rest = false;  ///< a lift: leave the realizations at rest where they are
    };
    Message broadcast(Message m) const;

    // What every rank does for a command (the root after broadcasting it, the others in
    // serve()).
    /// Returns the samples taken (fewer than `samples` when a stop was agreed; a sample in which
    /// a rank stopped on the signal is not taken).
    long do_run(long samples, ReferenceNeeds needs, coarse::BurstSamples* out);
    /// Collective: this rank's realizations back to `states` (the kept state, the resume point,
    /// a sample's start); a failure on any rank ends the run on all ("going back to WHERE").
    void restore_agreed(const std::vector<RealizationState>& states, const char* where);
    /// Root: at_rest_since_ from a new sample.
    void note_rest(const SampleRecord& rec);
    /// lift() and lift_apart() on the root: the command to the other ranks, then do_lift().
    void root_lift(const Eigen::VectorXd& target, const Eigen::MatrixXd* member_steps,
                   double new_time);
    void do_lift(double new_time, ReferenceNeeds needs, const Eigen::VectorXd* target, bool members,
                 bool hold, const Eigen::MatrixXd* member_steps = nullptr);
    std::filesystem::path do_checkpoint(long sequence, const CheckpointHeader* header,
                                        bool at_resume_point);
    void do_keep();
    void do_go_back();
    void do_confirm();
    /// `driver`: the loop's state (root; the workers keep none).
    void do_mark_resume_point(const DriverState& driver);
    void do_rebuild(ReferenceNeeds needs);
    void do_set_parameter(double value);

    /// Every rank: the snapshot of everything now (a failure to save on any rank ends the run
    /// on every rank together: RunFailed, and the root marks the run file).
    EnsembleSnapshot snapshot(const char* when) const;
    /// Every rank: back to `s` (realizations and the stepper's state). The cost counters keep
    /// counting the discarded work; `keep_membership`: who is in the ensemble and the failures
    /// survived stay as they are now (a rebuild decides them).
    void return_to(const EnsembleSnapshot& s, const char* when, bool keep_membership);
    std::string where_saved() const;
    /// Collective, after a stage every rank ran on its own (no collective inside): if it failed
    /// on any rank (`local_failure` non-empty there), every rank throws RunFailed with the
    /// lowest failing rank's message, naming the realization and the newest checkpoint.
    void agree_on_stage(const std::string& local_failure, long realization) const;

    const EnsembleLayout& layout_;
    Realizations local_;
    StepperSettings settings_;
    SampleSink* sink_;
    Progress* progress_;
    double wall_before_ = 0.0;  ///< resume_wall()
    EnsembleSampler sampler_;
    EnsembleLifting lifting_;
    EnsembleSnapshots snapshots_;
    FailureAgreement failures_;
    const CheckpointSink* writer_ = nullptr;
    bool periodic_checkpoints_ = false;
    std::filesystem::path last_checkpoint_;  ///< every rank: the newest checkpoint written
    double last_checkpoint_time_ = 0;
    double last_checkpoint_seconds_ = 0;
    long samples_taken_ = 0;  ///< every rank
    /// Root: end_state_since(); forgotten when a state is gone back to (re-judged from the next
    /// sample on: a bed at rest stays so).
    double at_rest_since_ = std::numeric_limits<double>::quiet_NaN();
    bool any_at_rest_ = false;  ///< root: any_at_rest()
    double particle_steps_ = 0;
    double micro_time_ = 0;
    double total_particles_ = 0;
    double record_seconds_ = 0;  ///< root: wall time giving samples to the sink
    int interrupted_ = 0;        ///< every rank: the agreed stop signal
    int finish_code_ = 0;
    bool injected_fired_ = false;  ///< the injected failure happens once
};

/// Thrown on the root by EnsembleStepper::run() in cpi when realizations failed and are to be
/// dropped or replaced: the driver calls rebuild_after_failure() and continues the loop from
/// the resume point.
class EnsembleChanged : public std::runtime_error {
  public:
    EnsembleChanged()
        : std::runtime_error("realizations failed; the coarse step is redone without them") {}
};

}  // namespace efdem::mpi_driver
