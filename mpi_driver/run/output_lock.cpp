#include "mpi_driver/run/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>
#include <system_error>

#include <fmt/format.h>

#include "core/error.hpp"

namespace efdem::mpi_driver {

namespace {
/// What the holder wrote into the lock file ("pid N on HOST"), for the message.
std::string holder(int fd) {
    char buf[256] = {};
    const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
    std::string text = n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
    while (!text.empty() && (text.back() == '\n' || text.back() == '\0')) text.pop_back();
    return text.empty() ? std::string("another process") : text;
}

[[noreturn]] void refuse(const Params& root, const std::filesystem::path& path, int fd) {
    const std::string who = holder(fd);
    ::close(fd);
    root.scope("output").fail(
        "prefix",
        fmt::format("another efdem run is writing under this prefix now ({} holds the lock {}); "
                    "two runs, or two restarts, never write one run's files (nothing was written)",
                    who, path.string()),
        "a prefix no running efdem uses; wait for that run to end, or stop it");
}
}  // namespace

std::filesystem::path OutputLock::path_of(const std::filesystem::path& directory,
                                          const std::string& prefix) {
    return directory / (prefix + ".lock");
}

OutputLock::OutputLock(const Params& root, const std::filesystem::path& directory,
                       const std::string& prefix)
    : path_(path_of(directory, prefix)) {
    // A run that ends removes its lock file while it holds the lock; a lock taken on a file
    // removed meanwhile is no lock, so the file is opened again until the locked one is there.
    for (;;) {
        fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (fd_ < 0)
            throw RuntimeFailure(fmt::format("cannot create the lock file {}: {}", path_.string(),
                                             std::strerror(errno)));
        if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
            const int fd = fd_;
            fd_ = -1;
            refuse(root, path_, fd);
        }
        struct stat held {
        }, named{};
        if (::fstat(fd_, &held) == 0 && ::stat(path_.c_str(), &named) == 0 &&
            held.st_ino == named.st_ino && held.st_dev == named.st_dev)
            break;
        ::close(fd_);
    }
    char host[256] = {};
    ::gethostname(host, sizeof host - 1);
    const std::string me = fmt::format("pid {} on {}\n", ::getpid(), host);
    if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, me.data(), me.size(), 0) < 0) {
        // Only the message of a refused second run is poorer without it.
    }
}

void OutputLock::check_free(const Params& root, const std::filesystem::path& directory,
                            const std::string& prefix) {
    const std::filesystem::path path = path_of(directory, prefix);
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return;  // no lock file: nobody holds it
    if (::flock(fd, LOCK_SH | LOCK_NB) != 0) refuse(root, path, fd);
    ::close(fd);
}

OutputLock::~OutputLock() {
    if (fd_ < 0) return;
    std::error_code ignored;
    std::filesystem::remove(path_, ignored);  // while still held: nobody can take a stale one
    ::close(fd_);
}

OutputLock::OutputLock(OutputLock&& other) noexcept
    : path_(std::move(other.path_)), fd_(other.fd_) {
    other.fd_ = -1;
}

}  // namespace efdem::mpi_driver
