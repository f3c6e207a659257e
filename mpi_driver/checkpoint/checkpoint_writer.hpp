#pragma once
/// \file
/// CheckpointWriter: writes one HDF5 file per checkpoint for the whole ensemble.
///
/// 1. collective (parallel HDF5, MPI-IO driver): every rank writes the rows of its own
///    realizations into shared datasets (rows in global realization order, so a checkpoint
///    written on P ranks restarts on any P' with the same number of realizations);
/// 2. the root reopens the file alone, adds the root-level state (CheckpointHeader: scene,
///    parameters, coarse-layer and driver state, the run's output files), the header checksum
///    and, last, the attribute complete = 1, and closes it;
/// 3. the file was written as `NAME.tmp`; the root renames it to NAME (atomic on POSIX) and
///    deletes all but the newest checkpoint.keep checkpoints.
///
/// A job killed at any moment therefore leaves the previous checkpoints untouched and at most
/// a `.tmp` file, which restart never picks (and which says it is incomplete if given).

#include <filesystem>
#include <string>
#include <vector>

#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_settings.hpp"
#include "mpi_driver/checkpoint_data/realization_state.hpp"
#include "mpi_driver/parallel/ensemble_layout.hpp"

namespace efdem::mpi_driver {

class CheckpointWriter final : public CheckpointSink {
  public:
    /// `identity`: mode, realizations, scene text and parameters (copied into every header);
    /// `outputs`: the run's output files, saved whole so that a restart continues them.
    CheckpointWriter(const EnsembleLayout& layout, const CheckpointSettings& settings,
                     std::string prefix, CheckpointHeader identity,
                     std::vector<std::filesystem::path> outputs);

    /// Collective. `header` (root only; ignored elsewhere) carries the stepper and driver
    /// state. Returns the path written. RuntimeFailure if the file cannot be written.
    std::filesystem::path write(long sequence, const std::vector<RealizationState>& local,
                                const CheckpointHeader* header) const override;

  private:
    /// Collective: CheckpointSpaceError on every rank when the directory has too little space.
    void ensure_space(const std::filesystem::path& path,
                      const std::vector<RealizationState>& local) const;
    void write_realizations(const std::filesystem::path& tmp,
                            const std::vector<RealizationState>& local) const;
    void write_header(const std::filesystem::path& tmp, long sequence,
                      const CheckpointHeader& header) const;
    void prune(const std::filesystem::path& current) const;

    const EnsembleLayout& layout_;
    CheckpointSettings settings_;
    std::string prefix_;
    CheckpointHeader identity_;
    std::vector<std::filesystem::path> outputs_;
};

}  // namespace efdem::mpi_driver
