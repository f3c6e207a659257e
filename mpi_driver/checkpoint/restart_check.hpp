#pragma once
/// \file
/// Whether a checkpoint may continue the run the current scene describes.
///
/// The realization count must match (a realization's state belongs to its global index). Every
/// parameter must have the value it had when the checkpoint was written, except those that do
/// not change the trajectory: run.duration (extend a run), output.*, checkpoint.*, restart.*,
/// debug.*, watchdog.*, ensemble.realizations_per_rank (the rank layout; results do not
/// depend on it), ensemble.at_rest, and bed.write, bed.read* (a restart neither writes nor reads
/// beds), and cpi.jump_until as long as the jumps the run made so far keep to the new value
/// (it ends the jumps from the checkpoint on, never before it). The mode and the observe.* keys
/// (the run file's grid) never change; other differences are refused unless
/// restart.allow_physics_change = true.

#include <filesystem>
#include <limits>
#include <string>

#include "core/param_table.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"

namespace efdem::mpi_driver {

/// Every resolved parameter as "key = value" lines (what a checkpoint stores).
std::string parameter_lines(const ParamTable& table);

/// Whether `key` may differ between a checkpoint and its restart.
bool may_change_on_restart(const std::string& key);

/// The observe.* keys: they shape the run file (its sample times, ICDF nodes, datasets), which a
/// restart continues; not even restart.allow_physics_change lets them change.
bool shapes_the_run_file(const std::string& key);

/// InputError (naming `path`) if the checkpoint cannot continue this run; returns a warning
/// (non-empty) when physics changes were allowed. `time_at_checkpoint` (the ensemble's clock in
/// the checkpoint; NaN: not known) refuses a run.duration that ends at or before it: such a
/// restart would have nothing to run, and would put the run's files back to the checkpoint; with
/// it, cpi.jump_until may change to any value not before the jumps made so far.
std::string check_restart(const std::filesystem::path& path, const CheckpointHeader& checkpoint,
                          const std::string& parameters_now, long realizations_now,
                          bool allow_physics_change,
                          double time_at_checkpoint = std::numeric_limits<double>::quiet_NaN());

}  // namespace efdem::mpi_driver
