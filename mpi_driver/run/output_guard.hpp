#pragma once
/// \file
/// The output guard: a run never destroys the output of an earlier one by accident.
///
/// At set-up (and in `efdem --check`) a new run refuses an output.directory it cannot write and
/// an output.prefix under which an earlier run left files (its run file, CSV files, VTK series,
/// thermo logs or checkpoints): exit 2, naming the file. output.overwrite = true replaces that
/// run: its files are all deleted first, so that none of them is left mixed with the new run's.
/// A restart (restart=FILE) writes only into the run its checkpoint came from: the run file
/// under its output.prefix, if there is one, must be that run's (same run_id), and so must the
/// newest checkpoint there; a prefix with none of a run's files is a fresh place to continue
/// the run (its outputs are put back there from the checkpoint).

#include <filesystem>
#include <string>
#include <vector>

#include "core/param_table.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/run/run_settings.hpp"

namespace efdem::mpi_driver {

/// The files of a run with `settings`' prefix that exist: in output.directory the run file,
/// the CSV files and their sidecar (_csv_meta.json), every realization's VTK series (.pvd,
/// .vtp) and thermo log (_thermo.csv); in checkpoint.directory its checkpoints; and the .tmp
/// files of any of them. Sorted.
std::vector<std::filesystem::path> existing_run_files(const RunSettings& settings);

/// Why `directory` cannot be written to (it or its nearest existing parent is not a writable
/// directory); empty if it can.
std::string unwritable_directory(const std::filesystem::path& directory);

/// InputError (naming output.directory or checkpoint.directory at its location in the scene)
/// if the directory cannot be written to (or created).
void check_output_is_writable(const Params& root, const RunSettings& settings);

/// InputError (naming output.prefix) if a new run (not `restarting`) would write over an
/// earlier run's files and output.overwrite is false.
void check_output_is_free(const Params& root, const RunSettings& settings, bool restarting);

/// InputError (naming bed.write) if a new run (not `restarting`) of `realizations` would write
/// over a bed file that exists (bed.write's NAME_rNNNN files) and output.overwrite is false.
void check_bed_write_is_free(const Params& root, const RunSettings& settings, long realizations,
                             bool restarting);

#if EFDEM_HAVE_HDF5
/// InputError (naming output.prefix) if a restart from `checkpoint` (whose header is `header`)
/// would write into another run's files (see above), or into files whose run cannot be told.
void check_restart_target(const Params& root, const RunSettings& settings,
                          const std::filesystem::path& checkpoint, const CheckpointHeader& header);
#endif

/// A new run with output.overwrite = true: deletes the earlier run's files; returns them.
std::vector<std::filesystem::path> remove_earlier_run(const RunSettings& settings);

}  // namespace efdem::mpi_driver
