#pragma once
/// \file
/// EnsembleSnapshot: the whole ensemble's state at one moment, in memory; EnsembleSnapshots: the
/// two places the EnsembleStepper keeps one, and the samples it holds back from the sink while
/// one may still be returned to (one job of the EnsembleStepper).
///
/// One snapshot type serves both uses:
///
///   kept state    adaptive CPI, reject-and-redo. keep_state() takes it before a projective
///                 jump; return_to_kept_state() goes back to it when the jump is rejected,
///                 confirm_kept_state() drops it when the jump is kept.
///   resume point  cpi, stops and failures. mark_resume_point() takes it between coarse steps
///                 (each one replaces the last; a rebuild after a failure takes it again);
///                 checkpoint_resume_point() writes it when a signal stops the run;
///                 rebuild_after_failure() goes back to it.
///
/// Which part is valid on which rank (the same for both uses, except the driver):
///
///   part of EnsembleSnapshot                     rank    kept state   resume point
///   realizations: RealizationState of each       every   its own k    its own k
///   time                                         every   yes          yes
///   stepper: counters, height range, active,     every   yes          yes
///     failures survived
///   stepper: lifting streams, warm starts of     root    yes          yes
///     the observables (meaningless elsewhere)
///   last_sample, coarse (its coarse vector)      root    yes (*)      yes
///   driver: the run loop's state                 root    no (empty)   yes
///
/// (*) return_to_kept_state() puts the last sample back but keeps the coarse vector of the
/// rejected burst's last sample, as the stepper did before this class existed (it matters only
/// to a rebuild that follows a resume point taken right after a rejection).
///
/// Phases: a kept state exists from keep_state() to confirm_kept_state() or
/// return_to_kept_state(), always inside one coarse step: there is none at a new resume point, a
/// checkpoint or a rebuild. A resume point exists from the first one of a cpi run to its end (a
/// direct run has none).
///
/// Samples: while a snapshot exists, a sample taken after it may still be taken back. The root
/// holds such samples (one list, in the order taken) and gives them to the sink when they can
/// no longer be: at the next resume point, at confirm_kept_state() when there is no resume point,
/// or before a checkpoint or the end of the run (release()); return_to_kept_state() drops those
/// taken after the kept state, rebuild_after_failure() all of them.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/checkpoint_data/realization_state.hpp"
#include "mpi_driver/ensemble/realization.hpp"
#include "mpi_driver/output/sample_sink.hpp"

namespace efdem::mpi_driver {

struct EnsembleSnapshot {
    std::vector<RealizationState> realizations;  ///< every rank: its local ones, in order
    double time = 0;                             ///< every rank: the ensemble's clock
    StepperState stepper;                        ///< every rank; root: all of it (above)
    SampleRecord last_sample;                    ///< root: the last sample before it
    Eigen::VectorXd coarse;                      ///< root: that sample's coarse vector
    DriverState driver;                          ///< root, resume point: the loop's state
};

class EnsembleSnapshots {
  public:
    enum class Use { kept, resume };

    /// `sink`: the root's (null elsewhere, or for no recording).
    explicit EnsembleSnapshots(SampleSink* sink) : sink_(sink) {}

    /// Every rank: this rank's realizations' states, and their restoration (bit for bit). What a
    /// realization throws passes through (the stepper ends the job: the ranks cannot agree).
    static std::vector<RealizationState> save_realizations(const Realizations& local);
    static void restore_realizations(Realizations& local,
                                     const std::vector<RealizationState>& states);

    bool has(Use use) const { return slot(use).has_value(); }
    const EnsembleSnapshot& get(Use use) const;

    /// The kept state: keep() (none kept yet), then confirm() (the samples since it count as
    /// taken) or go_back() (they are dropped; returns the snapshot to restore).
    void keep(EnsembleSnapshot snapshot);
    void confirm();
    EnsembleSnapshot go_back();
    /// The resume point: set_resume_point() replaces it (no kept state) and releases every held
    /// sample; back_to_resume_point() drops the kept state and every held sample (the caller
    /// restores get(Use::resume)).
    void set_resume_point(EnsembleSnapshot snapshot);
    void back_to_resume_point();

    /// Root: a sample, to the sink at once when no snapshot can take it back, else held.
    void record(const SampleRecord& sample);
    /// Root: the held samples that no kept state can take back, to the sink.
    void release();
    /// Root: samples held back now.
    std::size_t held() const { return held_.size(); }

  private:
    const std::optional<EnsembleSnapshot>& slot(Use use) const {
        return use == Use::kept ? kept_ : resume_;
    }

    SampleSink* sink_;
    std::optional<EnsembleSnapshot> kept_, resume_;
    std::vector<SampleRecord> held_;  ///< root: taken after a snapshot, in order
    std::size_t kept_from_ = 0;       ///< root: held_[kept_from_..] came after the kept state
};

}  // namespace efdem::mpi_driver
