#pragma once
/// \file
/// MpiSession: MPI start-up and shut-down as an object (RAII, like Kokkos::ScopeGuard), and the
/// two ways a run ends early.
///
/// * input errors are collective: every rank parsed the same text and fails the same way, so all
///   ranks return kExitInputError together (the root prints the message once);
/// * a failure seen by one rank while running (RuntimeFailure) is printed with the rank and
///   realization named, then MPI_Abort ends every rank: no rank waits forever in a collective.

#include <mpi.h>

#include <functional>
#include <optional>
#include <string>

namespace efdem::mpi_driver {

/// A communicator with its rank and size, and the way a rank-local failure ends the job.
class MpiComm {
  public:
    explicit MpiComm(MPI_Comm comm);
    MPI_Comm comm() const { return comm_; }
    int rank() const { return rank_; }
    int size() const { return size_; }
    bool is_root() const { return rank_ == 0; }
    /// Prints `message` (naming this rank), runs this process's last words (set_last_words;
    /// once) and aborts every rank with `exit_code`.
    [[noreturn]] void abort(const std::string& message, int exit_code) const;
    /// What this process does before it aborts, given the abort's message: the root marks its
    /// run file failed and frees its reserve. Empty function: nothing. A failure inside it is
    /// ignored (the abort goes on).
    static void set_last_words(std::function<void(const std::string&)> words);

  private:
    MPI_Comm comm_;
    int rank_ = 0;
    int size_ = 1;
};

class MpiSession {
  public:
    MpiSession(int* argc, char*** argv);
    ~MpiSession();
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;

    MPI_Comm comm() const { return MPI_COMM_WORLD; }
    int rank() const { return world_->rank(); }
    int size() const { return world_->size(); }
    bool is_root() const { return world_->is_root(); }
    /// MPI_COMM_WORLD with its rank and size.
    const MpiComm& world() const { return *world_; }

    /// If a process launcher (mpirun, srun) started several processes but this MPI library
    /// sees only one, the launcher belongs to another MPI: returns a message saying so.
    std::string launcher_mismatch() const;

    [[noreturn]] void abort(const std::string& message, int exit_code) const {
        world_->abort(message, exit_code);
    }

  private:
    std::optional<MpiComm> world_;
};

}  // namespace efdem::mpi_driver
