#pragma once
/// \file
/// Reading a whole-ensemble checkpoint (checkpoint_writer.hpp) for a restart. Every problem is
/// an InputError whose message starts with the file's path and says what is wrong: missing,
/// not HDF5 or truncated, interrupted while being written (no completeness marker), another
/// format version, a checksum mismatch (corrupted bytes), a realization it does not hold.
/// The file is opened read-only with the serial HDF5 driver by each rank that needs it, so a
/// bad file cannot leave ranks waiting inside a collective; the caller agrees on the verdict.

#include <filesystem>
#include <vector>

#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#include "mpi_driver/checkpoint_data/realization_state.hpp"

namespace efdem::mpi_driver {

/// Root: the validated root-level state (format version, marker, header checksum).
CheckpointHeader read_checkpoint_header(const std::filesystem::path& path);

/// Root: the time the checkpoint's ensemble had reached (the latest realization clock; a
/// realization dropped after a failure stopped earlier).
double read_checkpoint_time(const std::filesystem::path& path);

/// Realizations [first, first + count), each verified against its stored checksum.
std::vector<RealizationState> read_checkpoint_realizations(const std::filesystem::path& path,
                                                           long first, int count);

}  // namespace efdem::mpi_driver
