#pragma once
/// \file
/// Output that did not reach the disk: one message for every writer (VTK, thermo, CSV), naming
/// the file and the system's reason, and saying so plainly when the disk or quota is full.

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace efdem {

/// "cannot write <what> <path>: <strerror>" and, for ENOSPC/EDQUOT, "(no space left: the disk
/// or the quota is full)".
std::string io_failure_message(const std::filesystem::path& path, const std::string& what,
                               int error_number);

/// Flushes `f` and throws RuntimeFailure(io_failure_message(...)) if any write to it failed.
void flush_or_fail(std::FILE* f, const std::filesystem::path& path, const std::string& what);

/// Writes `bytes` to `<file>.tmp`, then renames it to `file`: a file cut short (a full disk) is
/// never left under the name of a whole one. RuntimeFailure(io_failure_message(file, what, ...))
/// (and no .tmp left) if it cannot.
void write_whole_file(const std::filesystem::path& file, std::string_view bytes,
                      const std::string& what);

}  // namespace efdem
