#pragma once
/// \file
/// EnsembleSampler: restriction of the whole ensemble at one sample (one job of the
/// EnsembleStepper).
///
/// Every rank observes its realizations (Realization::observe; a dropped realization gives a
/// row of NaN); the rows are gathered to the root in global realization order
/// (EnsembleLayout::gather_rows). The root averages the realizations in the ensemble in that
/// order (coarse::ensemble_mean), so the mean and the variance have the same bits on any rank
/// layout; it makes the SampleRecord, restricts the coarse vector with the observable and
/// appends both to the burst. Dropped realizations stay in the record as NaN rows, not in the
/// means.

#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "coarse/demixing/ensemble_observable.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "coarse/equation_free/coarse_stepper.hpp"
#include "dem/beds/bed_observation.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/ensemble/realization.hpp"
#include "mpi_driver/output/sample_sink.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"

namespace efdem::mpi_driver {

struct SamplingSettings {
    int quantiles = 19;  ///< m of the p-grid
    /// observe.bed: how the realizations measure the bed; none: not gathered.
    std::optional<dem::BedObservationSettings> bed;
    /// Root: an observable evaluated at every sample only to be recorded (e.g. the compact
    /// (A,B,C,D) of a direct run); null for none.
    coarse::EnsembleObservable* recorded = nullptr;
};

class EnsembleSampler {
  public:
    /// `observable` is used on the root only (every rank passes one).
    EnsembleSampler(const EnsembleLayout& layout, const SamplingSettings& settings,
                    coarse::EnsembleObservable& observable);

    /// Collective: one sample of every realization at `time`. `active` (every rank, per global
    /// realization): 1 in the ensemble. `needs`: the reference ICDFs to gather too (the same on
    /// every rank). Root: returns the record (also last()) and appends the sample to `out`
    /// (may be null); elsewhere returns null.
    const SampleRecord* take(const Realizations& local, const std::vector<char>& active,
                             double time, ReferenceNeeds needs, coarse::BurstSamples* out);

    /// Root: the last sample and its coarse vector (empty before the first sample).
    const SampleRecord& last() const { return last_; }
    const Eigen::VectorXd& last_coarse() const { return last_x_; }
    /// Root: put back a sample (a snapshot's): last() and, when given, last_coarse().
    void set_last(const SampleRecord& sample) { last_ = sample; }
    void set_last(const SampleRecord& sample, const Eigen::VectorXd& coarse) {
        last_ = sample;
        last_x_ = coarse;
    }
    /// Root: lowest and highest particle centre over the ensemble at the last sample [d_p].
    std::pair<double, double> height_range() const { return height_range_; }

    coarse::EnsembleObservable& observable() const { return *observable_; }
    void set_observable(coarse::EnsembleObservable& observable) { observable_ = &observable; }
    /// Root: the reference ICDFs samples need (the integrator's and the recorded observable's).
    ReferenceNeeds needs() const;
    const coarse::ProbabilityGrid& grid() const { return grid_; }

    /// Its part of the stepper's state: the height range (every rank) and the warm starts of
    /// the observables (meaningful on the root; restore() puts them back there only).
    void save(StepperState& s) const;
    void restore(const StepperState& s);

    /// Wall time in take() so far [s], and the samples taken.
    double seconds() const { return seconds_; }
    long count() const { return count_; }

  private:
    const EnsembleLayout& layout_;
    SamplingSettings settings_;
    coarse::EnsembleObservable* observable_;
    coarse::ProbabilityGrid grid_;
    SampleRecord last_;
    Eigen::VectorXd last_x_;
    std::pair<double, double> height_range_{0.0, 0.0};
    double seconds_ = 0;
    long count_ = 0;
};

}  // namespace efdem::mpi_driver
