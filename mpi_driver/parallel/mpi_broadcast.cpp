#include "mpi_driver/parallel/mpi_broadcast.hpp"

#include <vector>

namespace efdem::mpi_driver {

void broadcast_string(MPI_Comm comm, std::string& s) {
    unsigned long long n = s.size();
    MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, comm);
    s.resize(n);
    // Broadcast in chunks that fit an int count.
    constexpr unsigned long long chunk = 1ull << 30;
    for (unsigned long long off = 0; off < n; off += chunk) {
        const auto len = static_cast<int>(std::min(chunk, n - off));
        MPI_Bcast(s.data() + off, len, MPI_CHAR, 0, comm);
    }
}

Agreement agree_on_failure(MPI_Comm comm, int local_exit_code, const std::string& local_message) {
    Agreement a;
    MPI_Allreduce(&local_exit_code, &a.exit_code, 1, MPI_INT, MPI_MAX, comm);
    if (a.exit_code == 0) return a;
    int rank = 0, size = 1;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    // The lowest failing rank sends its message to rank 0.
    int candidate = local_exit_code != 0 ? rank : size;
    int first = size;
    MPI_Allreduce(&candidate, &first, 1, MPI_INT, MPI_MIN, comm);
    if (first == 0) {
        if (rank == 0) a.message = local_message;
        return a;
    }
    if (rank == first) {
        const int n = static_cast<int>(local_message.size());
        MPI_Send(&n, 1, MPI_INT, 0, 0, comm);
        MPI_Send(local_message.data(), n, MPI_CHAR, 0, 1, comm);
    } else if (rank == 0) {
        int n = 0;
        MPI_Recv(&n, 1, MPI_INT, first, 0, comm, MPI_STATUS_IGNORE);
        a.message.resize(static_cast<std::size_t>(n));
        MPI_Recv(a.message.data(), n, MPI_CHAR, first, 1, comm, MPI_STATUS_IGNORE);
        a.message = "[rank " + std::to_string(first) + "] " + a.message;
    }
    return a;
}

}  // namespace efdem::mpi_driver
