#pragma once
/// \file
/// Whether a checkpoint may continue the run the current scene describes.
///
/// The realization count must match (a realization's state belongs to its global index). Every
/// parameter must have the value it had when the checkpoint was written, except those that do
/// not change the trajectory: run.duration (extend a run), output.*, checkpoint.*, restart.*,
/// debug.*, watchdog.* and ensemble.realizations_per_rank (the rank layout; results do not
/// depend on it). Other differences are refused unless restart.allow_physics_change = true.

#include <filesystem>
#include <string>

#include "core/param_table.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"

namespace efdem::mpi_driver {

/// Every resolved parameter as "key = value" lines (what a checkpoint stores).
std::string parameter_lines(const ParamTable& table);

/// Whether `key` may differ between a checkpoint and its restart.
bool may_change_on_restart(const std::string& key);

/// InputError (naming `path`) if the checkpoint cannot continue this run; returns a warning
/// (non-empty) when physics changes were allowed.
std::string check_restart(const std::filesystem::path& path, const CheckpointHeader& checkpoint,
                          const std::string& parameters_now, long realizations_now,
                          bool allow_physics_change);

}  // namespace efdem::mpi_driver
