#include "core/io_error.hpp"

#include <cerrno>
#include <cstring>
#include <system_error>

#include <fmt/format.h>

#include "core/error.hpp"

namespace efdem {

std::string io_failure_message(const std::filesystem::path& path, const std::string& what,
                               int error_number) {
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

void write_whole_file(const std::filesystem::path& file, std::string_view bytes,
                      const std::string& what) {
    const std::filesystem::path tmp = file.string() + ".tmp";
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    int err = f ? 0 : errno;
    if (f) {
        if (std::fwrite(bytes.data(), 1, bytes.size(), f) != bytes.size() || std::fflush(f) != 0)
            err = errno ? errno : EIO;
        if (std::fclose(f) != 0 && err == 0) err = errno ? errno : EIO;
    }
    std::error_code ec;
    if (err == 0) std::filesystem::rename(tmp, file, ec);
    if (err == 0 && ec) err = ec.value();
    if (err != 0) {
        std::filesystem::remove(tmp, ec);
        throw RuntimeFailure(io_failure_message(file, what, err));
    }
}

}  // namespace efdem
