#pragma once
/// \file
/// EnsembleLifting: lift(X) of the whole ensemble (one job of the EnsembleStepper).
///
/// Every rank sends what lifting needs from each of its realizations (Realization::lift_input;
/// a DEM realization: particle heights and colours) to the root in realization order. The root
/// computes each realization's lifted state with the Lifter (a pure function) and that
/// realization's own `lifting` random stream, RandomStream(seed, r, "lifting"), so the result
/// does not depend on which rank holds realization r; it scatters the states back
/// (MPI_Scatterv) and every rank applies them and sets the clocks to the new time.
///
/// Two targets:
///
///   mean     every realization to the observable's lifting target of X;
///   members  (cpi.lift = members) realization r to X_r + (X - mean_r X_r): each keeps its
///            offset from the ensemble mean (one more gather: every realization's ICDF).
///            With member steps (cpi.lift = own), the k-th lifted realization moves by row k of
///            them on top (less the rows' mean: the mean still lands on X).
///
/// A lift can be limited to some realizations (`only`: a realization rebuilt after a failure).
///
/// Realizations at rest (cpi.at_rest = hold, Realization::at_rest: a DEM bed the gas no longer
/// moves) are left where they are: labels and state untouched, only their clocks follow the jump.
/// The others carry the ensemble's whole increment, so that the ensemble mean still lands on X:
/// with n lifted of which n_M move, the moving ones go to (n X - sum_rest X_r) / n_M (mean), or
/// each by (n X - sum_all X_r) / n_M on top of its own X_r (members), the member steps centred
/// over the moving ones (own). A realization that has stopped stays where it stopped, as it
/// would in a direct run: an absorbing state is not lifted away (docs/accuracy_vs_cost.md).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "coarse/demixing/ensemble_observable.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "coarse/equation_free/projective/projective_integrator.hpp"
#include "core/rng.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/ensemble/realization.hpp"
#include "mpi_driver/output/sample_sink.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"

namespace efdem::mpi_driver {

class EnsembleLifting {
  public:
    /// `lifter` is used on the root only; the root makes one lifting stream per realization.
    EnsembleLifting(const EnsembleLayout& layout, int quantiles, std::uint64_t seed,
                    const Lifter& lifter);

    /// What one lift does (the same on every rank, except `target`).
    struct Request {
        double new_time = 0;  ///< every lifted realization's clock afterwards
        /// The reference ICDF the observable's lifting target (and restrict_members) reads.
        coarse::ReferenceIcdf reference = coarse::ReferenceIcdf::none;
        bool members = false;  ///< cpi.lift = members (not with `only`)
        /// cpi.at_rest = hold: realizations at rest are not lifted (not with `only`); needs an
        /// observable that restricts members (their own X_r).
        bool hold_at_rest = false;
        const Eigen::VectorXd* target = nullptr;  ///< root: the coarse X; elsewhere null
        /// Root, with members: one row per lifted realization in realization order (the
        /// burst's members), added to its move; null, a row count that differs from the lifted
        /// realizations', or a non-finite row: the common increment alone.
        const Eigen::MatrixXd* member_steps = nullptr;
        /// Every rank, per global realization: lift only those marked 1 (null: all active), and
        /// leave the others' clocks alone (else a dropped realization's clock follows the jump).
        const std::vector<char>* only = nullptr;
    };
    /// Collective. `active`: per global realization, 1 in the ensemble (dropped ones are not
    /// lifted). `observable` (root): its lift_target() and, for members, restrict_members().
    void lift(Realizations& local, const std::vector<char>& active,
              coarse::EnsembleObservable& observable, const Request& request);

    /// Root: realization r gets a fresh stream of its own, never used before (a rebuilt
    /// realization: stream number r + R * failures).
    void renew_stream(long realization, long failures);
    /// Root: the stream of realization r (tests, checkpoints).
    const RandomStream& stream(long realization) const {
        return streams_[static_cast<std::size_t>(realization)];
    }

    /// Root: what the last lift did per realization.
    const LiftRecord& last() const { return last_; }
    /// Root: why the last lift failed for some realization ("realization r: why; ..."), or
    /// empty. Those realizations were left as they were.
    const std::string& last_failure() const { return failure_; }
    /// Root, with members: makes each realization's own target liftable (none: as computed).
    void set_member_repair(coarse::RepairHook repair) { member_repair_ = std::move(repair); }

    /// Its part of the stepper's state: the lifting streams (root only).
    void save(StepperState& s) const;
    void restore(const StepperState& s);

    /// Wall time in lift() so far [s], and the lifts done.
    double seconds() const { return seconds_; }
    long count() const { return count_; }

  private:
    const EnsembleLayout& layout_;
    coarse::ProbabilityGrid grid_;
    std::uint64_t seed_;
    const Lifter& lifter_;
    std::vector<RandomStream> streams_;  ///< root: one per realization
    coarse::RepairHook member_repair_;
    LiftRecord last_;
    std::string failure_;
    double seconds_ = 0;
    long count_ = 0;
};

}  // namespace efdem::mpi_driver
