#include "core/io_error.hpp"

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "core/error.hpp"

namespace efdem {

std::string io_failure_message(const std::filesystem::path& path, const std::string& what, int error_number) {
    const bool full = error_number == ENOSPC || error_number == EDQUOT;
    return fmt::format("cannot write {} {}: {}{}", what, path.string(),
                       error_number != 0 ? std::strerror(error_number) : "write failed",
                       full ? " (no space left: the disk or the quota is full)" : "");
}

void flush_or_fail(std::FILE* f, const std::filesystem::path& path, const std::string& what) {
    errno = 0;
    if (std::fflush(f) != 0 || std::ferror(f)) {
        const int err = errno != 0 ? errno : EIO;
        std::clearerr(f);
        throw RuntimeFailure(io_failure_message(path, what, err));
    }
}

}  // namespace efdem
