#pragma once
/// \file
/// CheckpointWriter: writes one HDF5 file per checkpoint for the whole ensemble.
///
/// 1. every rank sends its realizations' states to the root, one at a time, and the root writes
///    their rows into the /realizations datasets (rows in global realization order, so a
///    checkpoint written on P ranks restarts on any P' with the same number of realizations);
/// 2. the root adds the root-level state (CheckpointHeader: scene, parameters, coarse-layer and
///    driver state, the run's output files), the header checksum and, last, the attribute
///    complete = 1, and closes the file;
/// 3. the file was written as `NAME.tmp`; the root renames it to NAME (atomic on POSIX) and
///    deletes all but the newest checkpoint.keep checkpoints;
/// 4. the root tells every rank whether it worked: a failure anywhere (all of it is the root's)
///    is a CheckpointWriteError on every rank alike, and the `.tmp` is removed.
///
/// The root writes alone because a write that failed on one rank inside a collective MPI-IO call
/// could not be agreed on: that rank had to abort the job, leaving the run file `running`. The
/// price is the root's file system bandwidth for the whole ensemble (measured in
/// docs/performance.md); the root holds one realization's state at a time.
///
/// A job killed at any moment therefore leaves the previous checkpoints untouched and at most
/// a `.tmp` file, which restart never picks (and which says it is incomplete if given).

#include <filesystem>
#include <string>
#include <vector>

#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_settings.hpp"
#include "mpi_driver/checkpoint_data/realization_state.hpp"
#include "mpi_driver/output/h5_file.hpp"
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
    /// state. Returns the path written. CheckpointWriteError on every rank if it cannot be
    /// written (no space: CheckpointSpaceError, before anything is written).
    std::filesystem::path write(long sequence, const std::vector<RealizationState>& local,
                                const CheckpointHeader* header) const override;

  private:
    struct RowCounts {
        hsize_t particles = 0, pairs = 0;
    };
    /// Collective: the ensemble's particles and pair springs (known on the root only).
    RowCounts count_rows(const std::vector<RealizationState>& local) const;
    /// Collective: CheckpointSpaceError on every rank when the directory has too little space.
    void ensure_space(const std::filesystem::path& path, const RowCounts& counts) const;
    /// Root: receives every other rank's states and writes the whole checkpoint; returns the
    /// first failure's message (empty: written, renamed, older ones pruned).
    std::string write_on_root(const std::filesystem::path& final_path, long sequence,
                              const std::vector<RealizationState>& local, const RowCounts& counts,
                              const CheckpointHeader& header) const;
    void write_header(H5File& f, long sequence, const CheckpointHeader& header) const;
    void prune(const std::filesystem::path& current) const;

    const EnsembleLayout& layout_;
    CheckpointSettings settings_;
    std::string prefix_;
    CheckpointHeader identity_;
    std::vector<std::filesystem::path> outputs_;
};

}  // namespace efdem::mpi_driver
