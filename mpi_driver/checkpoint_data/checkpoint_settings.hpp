#pragma once
/// \file
/// CheckpointSettings: the keys of whole-ensemble checkpoints and restarts (the checkpoint room
/// reads its own keys). They are read in every run, so that a scene with a checkpoint block is
/// valid whether or not it checkpoints, and a restart may change them freely.
///
// clang-format off
/// | key                          | meaning                                              | default |
/// |------------------------------|------------------------------------------------------|---------|
/// | checkpoint.interval          | checkpoint every N coarse steps (cpi) or N samples   | 0 (off) |
/// |                              | (direct: N x observe.interval of DEM time)           |         |
/// | checkpoint.keep              | K: how many of the newest checkpoints are kept       | 2       |
/// | checkpoint.directory         | where checkpoints are written                        | output.directory |
/// | restart.allow_physics_change | accept a restart whose scene changes physics keys    | false   |
/// | debug.checkpoint_delay       | test only: seconds to sleep inside every checkpoint  | 0       |
/// |                              | write (after the root's own rows, before the rest)   |         |
// clang-format on

#include <filesystem>

#include "core/param_table.hpp"

namespace efdem::mpi_driver {

/// Whole-ensemble checkpoints (checkpoint_writer.hpp). interval = 0: none.
struct CheckpointSettings {
    long interval = 0;  ///< coarse steps (cpi) or samples (direct) between checkpoints
    int keep = 2;       ///< newest checkpoints kept on disk
    std::filesystem::path directory;
    bool allow_physics_change = false;  ///< restart.allow_physics_change
    double debug_delay = 0;             ///< seconds slept inside each write (kill tests)
    bool enabled() const { return interval > 0; }

    /// Reads the keys above; checkpoint.directory defaults to `output_directory`.
    static CheckpointSettings from_params(const Params& root,
                                          const std::filesystem::path& output_directory);
};

}  // namespace efdem::mpi_driver
