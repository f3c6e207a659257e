#include "mpi_driver/parallel/ensemble_layout.hpp"

#include <cstdint>
#include <numeric>

#include "core/contracts.hpp"

namespace efdem::mpi_driver {

namespace {
template <class T>
MPI_Datatype mpi_type();
template <>
MPI_Datatype mpi_type<double>() {
    return MPI_DOUBLE;
}
template <>
MPI_Datatype mpi_type<std::uint8_t>() {
    return MPI_UINT8_T;
}

/// Counts and displacements per rank of R arrays of the given lengths, k per rank.
void rank_layout(const std::vector<int>& lengths, int per_rank, int ranks, std::vector<int>& counts,
                 std::vector<int>& displs) {
    counts.assign(ranks, 0);
    for (std::size_t r = 0; r < lengths.size(); ++r)
        counts[static_cast<int>(r) / per_rank] += lengths[r];
    displs.assign(ranks, 0);
    std::partial_sum(counts.begin(), counts.end() - 1, displs.begin() + 1);
}
}  // namespace

EnsembleLayout::EnsembleLayout(const MpiComm& mpi, int per_rank)
    : mpi_(&mpi),
      per_rank_(per_rank),
      size_(mpi.size() * per_rank),
      first_(static_cast<long>(mpi.rank()) * per_rank) {
    EFDEM_EXPECTS(per_rank >= 1);
}

long EnsembleLayout::sum(long local) const {
    long total = 0;
    MPI_Allreduce(&local, &total, 1, MPI_LONG, MPI_SUM, mpi_->comm());
    return total;
}

Eigen::MatrixXd EnsembleLayout::gather_rows(const std::vector<Eigen::VectorXd>& rows) const {
    EFDEM_EXPECTS(static_cast<int>(rows.size()) == per_rank_);
    const Eigen::Index m = rows.front().size();
    std::vector<double> send(static_cast<std::size_t>(per_rank_ * m));
    for (int j = 0; j < per_rank_; ++j) {
        EFDEM_EXPECTS(rows[j].size() == m);
        std::copy(rows[j].data(), rows[j].data() + m, send.begin() + j * m);
    }
    // Row-major R x m on the root: rank-major order is global-index order.
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> all;
    if (is_root()) all.resize(size_, m);
    MPI_Gather(send.data(), static_cast<int>(send.size()), MPI_DOUBLE,
               is_root() ? all.data() : nullptr, static_cast<int>(send.size()), MPI_DOUBLE, 0,
               mpi_->comm());
    return is_root() ? Eigen::MatrixXd(all) : Eigen::MatrixXd();
}

template <class T>
std::vector<std::vector<T>> EnsembleLayout::gather_arrays(
    const std::vector<std::vector<T>>& local) const {
    EFDEM_EXPECTS(static_cast<int>(local.size()) == per_rank_);
    std::vector<int> lengths(per_rank_);
    std::vector<T> send;
    for (int j = 0; j < per_rank_; ++j) {
        lengths[j] = static_cast<int>(local[j].size());
        send.insert(send.end(), local[j].begin(), local[j].end());
    }
    std::vector<int> all_lengths(is_root() ? size_ : 0);
    MPI_Gather(lengths.data(), per_rank_, MPI_INT, all_lengths.data(), per_rank_, MPI_INT, 0,
               mpi_->comm());
    std::vector<int> counts, displs;
    std::vector<T> recv;
    if (is_root()) {
        rank_layout(all_lengths, per_rank_, mpi_->size(), counts, displs);
        recv.resize(static_cast<std::size_t>(displs.back() + counts.back()));
    }
    MPI_Gatherv(send.data(), static_cast<int>(send.size()), mpi_type<T>(), recv.data(),
                counts.data(), displs.data(), mpi_type<T>(), 0, mpi_->comm());
    std::vector<std::vector<T>> out;
    std::size_t offset = 0;
    for (int len : all_lengths) {
        out.emplace_back(
            recv.begin() + static_cast<std::ptrdiff_t>(offset),
            recv.begin() + static_cast<std::ptrdiff_t>(offset + static_cast<std::size_t>(len)));
        offset += static_cast<std::size_t>(len);
    }
    return out;
}

template <class T>
std::vector<std::vector<T>> EnsembleLayout::scatter_arrays(
    const std::vector<std::vector<T>>& on_root,
    const std::vector<std::size_t>& local_lengths) const {
    EFDEM_EXPECTS(static_cast<int>(local_lengths.size()) == per_rank_);
    std::vector<int> counts, displs;
    std::vector<T> send;
    if (is_root()) {
        EFDEM_EXPECTS(static_cast<int>(on_root.size()) == size_);
        std::vector<int> lengths;
        for (const auto& a : on_root) {
            lengths.push_back(static_cast<int>(a.size()));
            send.insert(send.end(), a.begin(), a.end());
        }
        rank_layout(lengths, per_rank_, mpi_->size(), counts, displs);
    }
    const std::size_t total =
        std::accumulate(local_lengths.begin(), local_lengths.end(), std::size_t{0});
    std::vector<T> recv(total);
    MPI_Scatterv(send.data(), counts.data(), displs.data(), mpi_type<T>(), recv.data(),
                 static_cast<int>(total), mpi_type<T>(), 0, mpi_->comm());
    std::vector<std::vector<T>> out;
    std::size_t offset = 0;
    for (std::size_t len : local_lengths) {
        out.emplace_back(recv.begin() + static_cast<std::ptrdiff_t>(offset),
                         recv.begin() + static_cast<std::ptrdiff_t>(offset + len));
        offset += len;
    }
    return out;
}

template std::vector<std::vector<double>> EnsembleLayout::gather_arrays(
    const std::vector<std::vector<double>>&) const;
template std::vector<std::vector<std::uint8_t>> EnsembleLayout::gather_arrays(
    const std::vector<std::vector<std::uint8_t>>&) const;
template std::vector<std::vector<double>> EnsembleLayout::scatter_arrays(
    const std::vector<std::vector<double>>&, const std::vector<std::size_t>&) const;
template std::vector<std::vector<std::uint8_t>> EnsembleLayout::scatter_arrays(
    const std::vector<std::vector<std::uint8_t>>&, const std::vector<std::size_t>&) const;

}  // namespace efdem::mpi_driver
