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
///
/// Only the root runs the macro integrator. The root's run()/lift() first broadcast a command;
/// the other ranks sit in serve(), which executes the same collectives, until finish().
/// A failure while running (e.g. a blown-up realization: the watchdog of dem::System) is printed
/// with the rank and realization named, and where the last checkpoint is, and MPI_Abort ends the
/// job: nobody waits in a collective.

#include <memory>
#include <utility>
#include <vector>

#include "coarse/equation_free/coarse_stepper.hpp"
#include "coarse/demixing/ensemble_observable.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "core/rng.hpp"
#include "mpi_driver/checkpoint/checkpoint_format.hpp"
#include "mpi_driver/ensemble/ensemble_layout.hpp"
#include "mpi_driver/ensemble/injected_failure.hpp"
#include "mpi_driver/output/progress.hpp"
#include "mpi_driver/ensemble/realization.hpp"
#include "mpi_driver/output/run_recorder.hpp"

namespace efdem::mpi_driver {

struct StepperSettings {
    double sample_interval = 0.5;     ///< time between samples [sqrt(d_p/g)]
    long steps_per_sample = 1;        ///< micro steps per sample
    int quantiles = 19;               ///< m of the p-grid
    std::uint64_t seed = 1;           ///< master seed (for the lifting streams)
    InjectedFailure failure;
    /// Root: an observable evaluated at every sample only to be recorded (e.g. the compact
    /// (A,B,C,D) of a direct run, for comparison with a compact CPI run); null for none.
    coarse::EnsembleObservable* recorded = nullptr;
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

    /// Root: write a whole-ensemble checkpoint numbered `sequence` with the driver's state
    /// (every rank joins through serve()). Needs set_checkpoint_writer(). Returns its path.
    std::filesystem::path checkpoint(long sequence, const DriverState& driver);
    /// Every rank: the writer used by checkpoint() (null: none).
    void set_checkpoint_writer(const CheckpointSink* writer) { writer_ = writer; }
    /// The coarse layer's state (root: all of it; elsewhere the counters), and its restoration
    /// on a restart (every rank; the lifting streams and warm starts matter on the root only).
    StepperState saved_state() const;
    void restore_state(const StepperState& state);
    long samples_taken() const { return samples_taken_; }

    /// Non-root ranks: execute the root's commands until finish(). Collective.
    void serve();
    /// Root: release the other ranks from serve().
    void finish();

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
    enum class Command : int { run = 1, lift = 2, finish = 3, checkpoint = 4, keep = 5, go_back = 6, confirm = 7 };
    /// The root's command, its argument, and whether the top-half ICDF is gathered (the
    /// observable lives on the root only and may change during a run: the workers must join
    /// exactly the collectives the root joins).
    struct Message {
        Command command;
        double value;
        bool top_half;
    };
    Message broadcast(Message m) const;
    void do_run(long samples, bool top_half, coarse::BurstSamples* out);
    void do_lift(double new_time, bool top_half, const Eigen::VectorXd* target);
    void take_sample(bool top_half, coarse::BurstSamples* out);
    std::filesystem::path do_checkpoint(long sequence, const CheckpointHeader* header);
    [[noreturn]] void fail(const std::string& message, long realization) const;
    void do_keep();
    void do_go_back();
    void do_confirm();

    const EnsembleLayout& layout_;
    std::vector<std::unique_ptr<Realization>> local_;
    StepperSettings settings_;
    coarse::EnsembleObservable* observable_;
    const Lifter& lifter_;
    RunRecorder* recorder_;
    Progress* progress_;
    const CheckpointSink* writer_ = nullptr;
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
    SampleRecord last_sample_;
    Overhead overhead_;
    bool provisional_ = false;               ///< between keep_state() and its end
    std::vector<RealizationState> kept_;     ///< every rank: its realizations' kept states
    StepperState kept_stepper_;
    SampleRecord kept_sample_;
    std::vector<SampleRecord> pending_;      ///< root: samples since keep_state()
};

}  // namespace efdem::mpi_driver
