#pragma once
/// \file
/// EnsembleObservable: how the root turns one ensemble sample into the coarse vector X that the
/// projective integrator sees, and how it turns a projected X back into each realization's
/// lifting target (the ICDF of the observed species that colour lifting must meet).
///
/// Inputs are per-realization ICDFs (matrices, row r = realization r): `icdf` of the observed
/// species (Q_L) on the p-grid (R x m) and the reference ICDF the observable asks for with
/// reference(): none; the top half (`top`, R x m, the ICDF of the N/2 highest particles, Q_top
/// of physics.md §8); or the whole bed (R x kWholeBedNodes, whole_bed_profile.hpp). Heights in
/// d_p. Generic: no DEM, no MPI.

#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/ensemble_statistics.hpp"  // ensemble_mean, ensemble_variance
#include "coarse/equation_free/projective/projective_integrator.hpp"

namespace efdem::coarse {

/// The ICDF of ALL particles (whatever their species) an observable reads next to Q_L.
enum class ReferenceIcdf {
    none,
    top_half,   ///< of the N/2 highest particles, on the p-grid (the compact observable)
    whole_bed,  ///< of every particle, at the kWholeBedNodes ranks (the rank observable)
};

class EnsembleObservable {
  public:
    virtual ~EnsembleObservable() = default;
    /// The name a scene gives it (cpi.observable), e.g. "icdf".
    virtual std::string_view name() const = 0;
    /// What it is, for messages, e.g. "full ICDF".
    virtual std::string_view label() const = 0;
    virtual Eigen::Index dimension() const = 0;
    /// Which reference ICDF restrict_*() and lift_target() read (their `top` argument).
    virtual ReferenceIcdf reference() const = 0;
    /// X of one sample. May carry state (e.g. a warm start); call once per sample, in time order.
    /// Returns a vector of NaN when X cannot be formed (the integrator then rejects the burst);
    /// status() says why.
    virtual Eigen::VectorXd restrict_ensemble(const Eigen::MatrixXd& icdf,
                                              const Eigen::MatrixXd& top) = 0;
    /// Whether restrict_members() forms each realization's own X (default: no).
    virtual bool restricts_members() const { return false; }
    /// Each realization's own X (R x dimension(), row r = realization r), whose column means
    /// are restrict_ensemble()'s X: what the statistical error of the slope is measured from.
    /// Empty when !restricts_members(). Keeps no state (a warm start belongs to the mean).
    virtual Eigen::MatrixXd restrict_members(const Eigen::MatrixXd& icdf,
                                             const Eigen::MatrixXd& top) const {
        (void)icdf;
        (void)top;
        return {};
    }
    /// The observed-species ICDF target for one realization, from the projected X and that
    /// realization's own reference ICDF (ignored when reference() is none).
    virtual Eigen::VectorXd lift_target(const Eigen::VectorXd& x,
                                        const Eigen::VectorXd& top) const = 0;
    /// 0 when the last restrict_ensemble() succeeded; a message otherwise.
    virtual int status() const { return 0; }
    virtual std::string status_message() const { return {}; }
    /// Why the most recent restriction that failed (returned NaN) failed, kept through later
    /// successes: a burst is rejected for its first failed sample, not its last one. Empty if
    /// none failed.
    virtual std::string failure_message() const { return {}; }
    /// Why the last rejected burst's restriction failed: failure_message(), else
    /// status_message(), else a generic text. For the log line of a fallback.
    std::string failure_reason() const;
    /// The lowest and highest height a lifting target may use [d_p], asked for when a
    /// projected vector is repaired (the heights the particles occupy at the last sample).
    using FeasibleRange = std::function<std::pair<double, double>()>;
    /// What makes a projected X liftable (empty: X needs no repair).
    virtual RepairHook repair_hook(FeasibleRange range) const {
        (void)range;
        return {};
    }
    /// The share of all particles that are of the observed species (the same in every
    /// realization: a lift changes labels, not counts), told at every sample before
    /// restrict_ensemble(); NaN when the micro model does not say. An observable whose repair
    /// needs it (RankObservable: no interval can hold more lights than particles) keeps it.
    virtual void set_observed_fraction(double fraction) { (void)fraction; }
    /// State carried from sample to sample (a warm start), for checkpoints; empty if none.
    virtual std::vector<double> saved_state() const { return {}; }
    virtual void restore_state(const std::vector<double>& state) { (void)state; }
};

/// X = the ensemble-mean ICDF of the observed species (m nodes); every realization is lifted to
/// X itself (physics.md §9).
class IcdfObservable final : public EnsembleObservable {
  public:
    explicit IcdfObservable(Eigen::Index m) : m_(m) {}
    std::string_view name() const override { return "icdf"; }
    std::string_view label() const override { return "full ICDF"; }
    Eigen::Index dimension() const override { return m_; }
    ReferenceIcdf reference() const override { return ReferenceIcdf::none; }
    Eigen::VectorXd restrict_ensemble(const Eigen::MatrixXd& icdf,
                                      const Eigen::MatrixXd& top) override;
    Eigen::VectorXd lift_target(const Eigen::VectorXd& x,
                                const Eigen::VectorXd& top) const override;
    /// Each realization's X is its own ICDF: the rows of `icdf` themselves.
    bool restricts_members() const override { return true; }
    Eigen::MatrixXd restrict_members(const Eigen::MatrixXd& icdf,
                                     const Eigen::MatrixXd& top) const override;
    /// Projected ICDFs are made non-decreasing and clipped into the feasible range before
    /// lifting (physics.md §9 step 1; coarse/demixing/monotone_repair.hpp).
    RepairHook repair_hook(FeasibleRange range) const override;

  private:
    Eigen::Index m_;
};

}  // namespace efdem::coarse
