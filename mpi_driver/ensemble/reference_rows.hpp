#pragma once
/// \file
/// ReferenceRows: the reference ICDFs of all particles (the top half, the whole bed) that the
/// observables ask for, collected from this rank's realizations and gathered on the root in
/// realization order. What a sample (EnsembleSampler) and a lift (EnsembleLifting) share.

#include <vector>

#include <Eigen/Core>

#include "mpi_driver/ensemble/realization.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"

namespace efdem::mpi_driver {

class ReferenceRows {
  public:
    /// `m`: the p-grid's nodes (the top half's length).
    ReferenceRows(ReferenceNeeds needs, Eigen::Index m) : needs_(needs), m_(m) {}
    /// The next local realization's rows, taken from its observation.
    void add(Observation& o);
    /// The next local realization reports none (dropped, not lifted): rows of NaN.
    void add_missing();
    /// Collective: gathers every kind asked for; the root then has R rows of each.
    void gather(const EnsembleLayout& layout);
    /// Root, after gather(): the R x n rows of `kind` (empty when not asked for or none).
    const Eigen::MatrixXd& rows(coarse::ReferenceIcdf kind) const;

  private:
    ReferenceNeeds needs_;
    Eigen::Index m_;
    std::vector<Eigen::VectorXd> top_, bed_;
    Eigen::MatrixXd all_top_, all_bed_, none_;
};

}  // namespace efdem::mpi_driver
