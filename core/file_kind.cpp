#include "core/file_kind.hpp"

#include <sys/stat.h>
#include <cerrno>
#include <cstring>
#include <system_error>

#include <fmt/format.h>

namespace efdem {

std::string not_a_regular_file(const std::filesystem::path& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
        const int err = errno;
        if (err == ELOOP) return "is a symbolic link that loops (it never reaches a file)";
        if (err == ENOENT) {
            struct stat link {};
            std::error_code ec;
            if (::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode))
                return fmt::format("is a symbolic link to '{}', which does not exist",
                                   std::filesystem::read_symlink(path, ec).string());
            return "file not found";
        }
        return fmt::format("cannot be reached: {}", std::strerror(err));
    }
    if (S_ISREG(st.st_mode)) return {};
    if (S_ISDIR(st.st_mode)) return "is a directory, not a file";
    if (S_ISFIFO(st.st_mode)) return "is a FIFO (named pipe), not a file";
    if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) return "is a device, not a file";
    if (S_ISSOCK(st.st_mode)) return "is a socket, not a file";
    return "is not a regular file";
}

}  // namespace efdem
