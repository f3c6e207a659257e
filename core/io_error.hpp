#pragma once
/// \file
/// Output that did not reach the disk: one message for every writer (VTK, thermo, CSV), naming
/// the file and the system's reason, and saying so plainly when the disk or quota is full.

#include <cstdio>
#include <filesystem>
#include <string>

namespace efdem {

/// "cannot write <what> <path>: <strerror>" and, for ENOSPC/EDQUOT, "(no space left: the disk
/// or the quota is full)".
std::string io_failure_message(const std::filesystem::path& path, const std::string& what, int error_number);

/// Flushes `f` and throws RuntimeFailure(io_failure_message(...)) if any write to it failed.
void flush_or_fail(std::FILE* f, const std::filesystem::path& path, const std::string& what);

}  // namespace efdem
