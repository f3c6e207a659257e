#pragma once
/// \file
/// What the ensemble reports, and SampleSink: the only way its samples and survived failures
/// leave it (EnsembleStepper calls sample() and failure() on the root, nothing else). The run's
/// recorders (run_recorder.hpp) implement it; the ensemble does not know them.

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace efdem::mpi_driver {

/// The bed quantities of an ensemble sample (observe.bed; dem/beds/bed_observation.hpp): one
/// row per realization (NaN rows for dropped ones), or a single row for the ensemble mean.
struct BedRecord {
    Eigen::VectorXd pressure_drop;        ///< Delta P [rho_s g d_p]
    Eigen::VectorXd pressure_drop_ratio;  ///< Delta P / (W / A) [-]
    Eigen::VectorXd height;               ///< bed height (99 % of the particle volume below) [d_p]
    Eigen::VectorXd mixing_index;         ///< Lacey index of the observed species [-]
    Eigen::MatrixXd species_height;       ///< rows x species: mean centre height [d_p]
    Eigen::MatrixXd solid_fraction;       ///< rows x slabs: phi(z) [-]
    bool empty() const { return pressure_drop.size() == 0; }
};

/// One ensemble sample, as the root sees it. Heights in d_p, time in sqrt(d_p/g).
struct SampleRecord {
    double time = 0;
    Eigen::VectorXd mean;          ///< ensemble-mean ICDF of the observed species (m)
    Eigen::VectorXd variance;      ///< unbiased ensemble variance per node (zeros when R = 1)
    Eigen::MatrixXd realizations;  ///< R x m: each realization's ICDF
    Eigen::VectorXd com;           ///< R: centre-of-mass height of each realization
    /// R: 1 where the realization is at rest (Realization::at_rest), 0 where it moves, NaN where
    /// it was dropped.
    Eigen::VectorXd at_rest;
    /// R x 4: each realization's thermo numbers (ThermoNumbers: KE per particle, contacts per
    /// particle, largest overlap, neighbour-list builds); NaN where dropped or not measured.
    Eigen::MatrixXd thermo;
    /// observe.bed: each realization's bed quantities and their mean over the realizations in
    /// the ensemble; empty otherwise.
    BedRecord bed;
    BedRecord bed_mean;
    Eigen::VectorXd top_mean;  ///< ensemble-mean ICDF of the N/2 highest particles, when gathered
    Eigen::VectorXd compact;   ///< (A, B, C, D) of the mean y(p), when used (else empty)
    int compact_status = 0;    ///< 0 ok; otherwise the fit's status code
    /// Realizations in the means (R less those dropped after a failure; their rows are NaN).
    int realizations_used = 0;
};

/// A realization that failed and what the ensemble did about it (ensemble.on_failure).
struct FailureRecord {
    double time = 0;  ///< when it failed
    long realization = -1;
    std::string reason;         ///< the failure's message
    std::string action;         ///< "dropped", "replaced", or "fatal" (the run ends)
    long donor = -1;            ///< replaced: the realization whose state it was rebuilt from
    double resumed_at = 0;      ///< cpi: where the interrupted coarse step was redone from
    int realizations_left = 0;  ///< realizations in the ensemble after it
};

/// What lifting did to each realization at one coarse step.
struct LiftRecord {
    std::vector<long> changed;  ///< labels changed or particles moved, per realization
    /// What `changed` counts: "labels changed" (colour lifting) or "particles moved".
    std::string changed_what = "labels changed";
    std::vector<double> max_deviation;  ///< max |Q_L,lifted - target| per realization [d_p]
    /// The lift's error in the ensemble mean: RMS over the p-grid of the mean over the lifted
    /// realizations (those held at rest count with 0) of achieved - target [d_p], the norm the
    /// adaptive controller's tolerance is in; NaN when no realization was lifted.
    double error = std::numeric_limits<double>::quiet_NaN();
    std::vector<std::string> messages;  ///< non-empty where a target was repaired or clipped
    std::vector<char> at_rest;  ///< 1 where the realization was at rest and left where it was
};

/// Where the root's samples and survived failures go (a RunRecorder, or a test's list).
class SampleSink {
  public:
    virtual ~SampleSink() = default;
    /// One ensemble sample, once it can no longer be taken back (not while a kept state or a
    /// resume point may still be returned to: EnsembleSnapshots holds it back until then).
    virtual void sample(const SampleRecord& s) = 0;
    /// A realization's failure that the run survived (drop, replace).
    virtual void failure(const FailureRecord& f) = 0;
};

}  // namespace efdem::mpi_driver
