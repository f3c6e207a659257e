#pragma once
/// \file
/// Small typed wrappers over MPI collectives used by the driver.

#include <mpi.h>

#include <string>

namespace efdem::mpi_driver {

/// Broadcasts a string from rank 0 (collective).
void broadcast_string(MPI_Comm comm, std::string& s);

/// Collective agreement after a local step that may have failed: returns the largest exit code
/// over all ranks and, on rank 0, the message of the lowest failing rank (empty if none failed).
struct Agreement {
    int exit_code = 0;
    std::string message;
};
Agreement agree_on_failure(MPI_Comm comm, int local_exit_code, const std::string& local_message);

}  // namespace efdem::mpi_driver
