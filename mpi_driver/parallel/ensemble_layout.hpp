#pragma once
/// \file
/// EnsembleLayout: how the R = P x k realizations sit on the P ranks, and the collectives over
/// all of them.
///
/// Realization r (global index) lives on rank r / k as local realization r % k. Everything
/// gathered to the root is ordered by global index, so the root's results (means, lifts) do
/// not depend on how realizations are spread over ranks.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "mpi_driver/parallel/mpi_session.hpp"

namespace efdem::mpi_driver {

class EnsembleLayout {
  public:
    EnsembleLayout(const MpiComm& mpi, int per_rank);

    int size() const { return size_; }           ///< R
    int per_rank() const { return per_rank_; }   ///< k
    long first_index() const { return first_; }  ///< global index of this rank's first realization
    const MpiComm& mpi() const { return *mpi_; }
    bool is_root() const { return mpi_->is_root(); }
    /// Sum of a per-rank count over all ranks (collective).
    long sum(long local) const;

    /// Gathers one vector of length m per local realization; on the root returns the R x m
    /// matrix (row r = realization r), elsewhere an empty matrix. Collective.
    Eigen::MatrixXd gather_rows(const std::vector<Eigen::VectorXd>& local_rows) const;
    /// Gathers one array per local realization (lengths may differ); the root gets R arrays,
    /// the other ranks none. Collective.
    template <class T>
    std::vector<std::vector<T>> gather_arrays(const std::vector<std::vector<T>>& local) const;
    /// Sends array r from the root to realization r; `local_lengths` are the lengths this rank
    /// expects for its k realizations. Collective.
    template <class T>
    std::vector<std::vector<T>> scatter_arrays(const std::vector<std::vector<T>>& on_root,
                                               const std::vector<std::size_t>& local_lengths) const;

  private:
    const MpiComm* mpi_;
    int per_rank_;
    int size_;
    long first_;
};

}  // namespace efdem::mpi_driver
