#pragma once
/// \file
/// FailureAgreement: who is in the ensemble, and the ranks' agreement on failures and stop
/// signals after every sample (one job of the EnsembleStepper).
///
/// agree() is one MPI_Allreduce of (stop signal, failures on this rank, sample cut short): every
/// rank learns at the same sample that a signal arrived somewhere or that a realization failed, so
/// no rank waits in a collective the others left. On failures a second MPI_Allreduce tells every
/// rank which realizations failed, and the policy (failure_policy.hpp) decides, the same on every
/// rank:
///
/// * abort, or more failures than the policy survives: every failing rank prints its failures
///   (rank and realization named, and where the newest checkpoint is), the root gathers the
///   messages, and every rank throws RunFailed;
/// * direct run (no resume point to redo the step from): the failed realizations leave the
///   ensemble at once (drop); the root gives the FailureRecord to the sink;
/// * cpi: the failures are pending(); the stepper goes back to the resume point, and then
///   plan_rebuild() drops each failed realization or picks its donor (the next healthy one),
///   send_donor_states() copies the donor's state at the resume point to the failed one's
///   rank, and finish_rebuild() records what was done.
///
/// active() (per global realization: 1 in the ensemble) is the same on every rank.

#include <functional>
#include <string>
#include <vector>

#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/checkpoint_data/realization_state.hpp"
#include "mpi_driver/ensemble/failure_policy.hpp"
#include "mpi_driver/ensemble/realization.hpp"
#include "mpi_driver/output/sample_sink.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"

namespace efdem::mpi_driver {

/// A local realization's failure: its global index and the message.
struct RealizationFailure {
    long realization = -1;
    std::string message;
};

class FailureAgreement {
  public:
    /// `where_saved`: the sentence naming the newest checkpoint (for the failure messages).
    FailureAgreement(const EnsembleLayout& layout, const FailurePolicy& policy,
                     std::function<std::string()> where_saved);

    /// What the ranks agreed on after a sample.
    struct Agreed {
        int signal = 0;    ///< the stop signal (the largest received; 0: none)
        bool cut = false;  ///< some rank stopped inside the sample: nobody may use it
    };
    /// Collective, every rank after every sample. `mine`: this rank's failures; `signal`: the
    /// stop signal this rank received (0: none); `cut`: this rank's realizations stopped inside
    /// the sample on it. `can_redo`: a resume point exists (cpi), so failures wait for a rebuild
    /// (pending()); else they are dropped now. `sink` (root, may be null): where a survived
    /// failure is recorded. Throws RunFailed on every rank when the run cannot survive the
    /// failures.
    Agreed agree(const Realizations& local, const std::vector<RealizationFailure>& mine, int signal,
                 bool cut, bool can_redo, SampleSink* sink);

    /// Every rank: failures agreed on that await a rebuild.
    bool pending() const { return !pending_.empty(); }
    /// Every rank: per global realization, 1 in the ensemble.
    const std::vector<char>& active() const { return active_; }
    bool is_active(long realization) const {
        return active_[static_cast<std::size_t>(realization)] != 0;
    }
    int active_count() const;
    /// Failures survived so far.
    long failures() const { return failures_; }
    /// This rank's clock of the ensemble: that of its first realization in the ensemble (else of
    /// its first one: a dropped realization's clock moves on with the ensemble's).
    double time(const Realizations& local) const;

    /// Its part of the stepper's state (every rank): active and failures survived.
    void save(StepperState& s) const;
    void restore(const StepperState& s);

    /// What a rebuild does, the same on every rank.
    struct Rebuild {
        bool replace = false;       ///< ensemble.on_failure = replace (else drop)
        std::vector<long> failed;   ///< the failed realizations, ascending
        std::vector<long> donors;   ///< per failed: the donor (-1: none, it keeps its own state)
        std::vector<char> rebuilt;  ///< per global realization: 1 if rebuilt (to be lifted)
    };
    /// Every rank, after going back to the resume point: drops the pending failed realizations,
    /// or (replace) chooses each one's donor: the next realization in the ensemble that did not
    /// fail; none when `can_lift` is false (before the first coarse step there is no coarse state
    /// to lift a copy to, so it restarts from its own state).
    Rebuild plan_rebuild(bool can_lift);
    /// Every rank: each donor's state at the resume point (`at_resume`: this rank's) goes to the
    /// failed realization's rank (point to point) and is restored there under the failed index.
    void send_donor_states(const Rebuild& plan, const std::vector<RealizationState>& at_resume,
                           Realizations& local) const;
    /// Root: the FailureRecords of the rebuild to `sink` (`resumed_at`: the resume point's time);
    /// every rank: nothing pending any more.
    void finish_rebuild(const Rebuild& plan, double resumed_at, SampleSink* sink);

  private:
    [[noreturn]] void fail_agreed(const Realizations& local,
                                  const std::vector<RealizationFailure>& failures) const;
    void on_failures(const Realizations& local, const std::vector<RealizationFailure>& failures,
                     bool can_redo, SampleSink* sink);
    /// Root: every realization's failure message (empty where none); collective.
    std::vector<std::string> gather_messages(const Realizations& local,
                                             const std::vector<RealizationFailure>& failures) const;

    const EnsembleLayout& layout_;
    FailurePolicy policy_;
    std::function<std::string()> where_saved_;
    std::vector<char> active_;                  ///< every rank: per realization, in the ensemble
    long failures_ = 0;                         ///< every rank: failures survived
    std::vector<long> pending_;                 ///< every rank: failed, awaiting the rebuild
    std::vector<std::string> pending_reasons_;  ///< root: why (per realization)
    double pending_time_ = 0;                   ///< when they failed
};

/// Every rank, when the ensemble agreed that a realization failed (its rank printed why).
class RunFailed : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

}  // namespace efdem::mpi_driver
