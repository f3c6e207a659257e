#pragma once
/// \file
/// Loading a restart collectively: the root reads and validates the checkpoint's root-level
/// state and checks that it fits the scene (restart_check.hpp); every rank then reads and
/// verifies its own realizations. Each stage ends with agree_on_failure, so a bad checkpoint
/// stops every rank with the root's one message and exit code 2, never a hang.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/checkpoint_data/realization_state.hpp"
#include "mpi_driver/parallel/mpi_broadcast.hpp"
#include "mpi_driver/parallel/mpi_session.hpp"

namespace efdem::mpi_driver {

struct RestartData {
    std::filesystem::path path;
    CheckpointHeader header;  ///< root: complete; elsewhere only header.stepper counters
    std::vector<RealizationState> local;  ///< this rank's realizations
};

/// Collective. `parameters`: the current scene's parameter_lines(). The agreement's exit code
/// is 0 when `out` is ready.
Agreement load_restart(const MpiComm& mpi, const std::filesystem::path& path,
                       const std::string& parameters, int per_rank, bool allow_physics_change,
                       RestartData& out);

/// Root: puts the run's output files back as they were at the checkpoint, so that the
/// recorders continue them (RuntimeFailure if a file cannot be written).
void restore_outputs(const CheckpointHeader& header, const std::filesystem::path& directory,
                     const std::string& prefix);

}  // namespace efdem::mpi_driver
