#pragma once
/// \file
/// Rank-aware logging. core knows no MPI: the driver tells the logger which rank it is on.
///
/// * info(): progress and parameters; printed by the root rank only (to stdout).
/// * warn(): printed by whichever rank calls it, prefixed with the rank when there are several
///   (to stderr), so that a warning seen on one rank only is not lost.
/// * error(): the final message of a failing run (stderr), always printed.
/// * rank_error(), rank_warn(): what only this rank sees (a realization's failure), "efdem:
///   [rank r of n] error: ..." (warning: ...) on stderr, always printed, whatever the rank count.
/// * notice(): the final message of a run that ends without failing but unfinished (a stop
///   signal: where it was saved, how to continue), "efdem: ..." on stderr, always printed.
/// * output(): what a command prints as its answer (--help, --list-effects, --check, ...):
///   stdout on the root, whatever the level.
///
/// The root also keeps a copy of everything it prints in a file (open_copy(): the run's
/// PREFIX_log.txt); what it printed before the file was opened (the header, settling) is kept in
/// memory and written first.

#include <filesystem>
#include <string>
#include <utility>

#include <fmt/format.h>

namespace efdem::log {

enum class Level { quiet = 0, warn = 1, info = 2, debug = 3 };

/// Called once by the driver after MPI start-up (defaults: rank 0 of 1, Level::info).
void configure(int rank, int n_ranks, Level level);
Level level();
int rank();

/// Root: from now on every line it prints also goes to `path`, after `preamble` (what is not
/// printed on the screen, e.g. the scene as read) and the lines printed so far. The file is
/// appended to, or replaced with `replace`. Returns "" or why the file cannot be written.
std::string open_copy(const std::filesystem::path& path, bool replace, const std::string& preamble);

void write_info(const std::string& message);
void write_warn(const std::string& message);
void write_error(const std::string& message);
void write_debug(const std::string& message);
void write_notice(const std::string& message);
void write_rank_error(const std::string& message);
void write_rank_warn(const std::string& message);
void write_output(const std::string& message);

template <class... Args>
void info(fmt::format_string<Args...> f, Args&&... args) {
    if (level() >= Level::info && rank() == 0)
        write_info(fmt::format(f, std::forward<Args>(args)...));
}
template <class... Args>
void debug(fmt::format_string<Args...> f, Args&&... args) {
    if (level() >= Level::debug) write_debug(fmt::format(f, std::forward<Args>(args)...));
}
template <class... Args>
void warn(fmt::format_string<Args...> f, Args&&... args) {
    if (level() >= Level::warn) write_warn(fmt::format(f, std::forward<Args>(args)...));
}
template <class... Args>
void rank_error(fmt::format_string<Args...> f, Args&&... args) {
    write_rank_error(fmt::format(f, std::forward<Args>(args)...));
}
template <class... Args>
void rank_warn(fmt::format_string<Args...> f, Args&&... args) {
    write_rank_warn(fmt::format(f, std::forward<Args>(args)...));
}
template <class... Args>
void notice(fmt::format_string<Args...> f, Args&&... args) {
    write_notice(fmt::format(f, std::forward<Args>(args)...));
}
/// `text` as it is (no newline added), on the root only.
inline void output(const std::string& text) {
    if (rank() == 0) write_output(text);
}
template <class... Args>
void error(fmt::format_string<Args...> f, Args&&... args) {
    write_error(fmt::format(f, std::forward<Args>(args)...));
}

}  // namespace efdem::log
