#pragma once
/// \file
/// One run at a time under an output prefix. The root of a run (and of a restart) holds an
/// advisory lock (flock) on `<output.directory>/<output.prefix>.lock` from set-up to its end,
/// so that a second run or restart into the same prefix is refused (exit 2) instead of the two
/// writing one run file. The system drops the lock when the process ends, however it ends: a
/// lock file left behind by a killed run does not block the next one. The file is removed at
/// the end of the run; it is not one of the run's files (output_guard.hpp).

#include <filesystem>
#include <string>

#include "core/param_table.hpp"

namespace efdem::mpi_driver {

class OutputLock {
  public:
    /// Takes the lock (creating the lock file; output.directory must exist); InputError naming
    /// output.prefix if another process holds it.
    OutputLock(const Params& root, const std::filesystem::path& directory,
               const std::string& prefix);
    /// --check: InputError, as above, if another process holds the lock; creates nothing.
    static void check_free(const Params& root, const std::filesystem::path& directory,
                           const std::string& prefix);
    ~OutputLock();
    OutputLock(OutputLock&& other) noexcept;
    OutputLock& operator=(OutputLock&&) = delete;
    OutputLock(const OutputLock&) = delete;
    OutputLock& operator=(const OutputLock&) = delete;

    static std::filesystem::path path_of(const std::filesystem::path& directory,
                                         const std::string& prefix);

  private:
    std::filesystem::path path_;
    int fd_ = -1;
};

}  // namespace efdem::mpi_driver
