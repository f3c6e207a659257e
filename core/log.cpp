#include "core/log.hpp"

#include <cstdio>
#include <fstream>
#include <memory>

namespace efdem::log {

namespace {
int g_rank = 0;
int g_n_ranks = 1;
Level g_level = Level::info;

std::string rank_prefix() {
    return g_n_ranks > 1 ? fmt::format("[rank {}] ", g_rank) : "";
}

// The root's copy of what it prints (open_copy()); before it is open, the lines so far (up to
// kPendingLimit bytes: the start of a run, not a run's worth).
std::unique_ptr<std::ofstream> g_copy;
std::string g_pending;
constexpr std::size_t kPendingLimit = 1 << 22;

void copy(const std::string& text) {
    if (g_rank != 0) return;
    if (g_copy) {
        *g_copy << text;
        g_copy->flush();  // a killed job keeps its log up to the last line
    } else if (g_pending.size() + text.size() <= kPendingLimit) {
        g_pending += text;
    }
}

/// Prints `text` to `stream` and keeps the root's copy.
void print(std::FILE* stream, const std::string& text) {
    std::fputs(text.c_str(), stream);
    std::fflush(stream);
    copy(text);
}
}  // namespace

std::string open_copy(const std::filesystem::path& path, bool replace,
                      const std::string& preamble) {
    auto f = std::make_unique<std::ofstream>(path, replace ? std::ios::trunc : std::ios::app);
    if (!*f) return fmt::format("{} cannot be opened for writing", path.string());
    *f << preamble << g_pending;
    f->flush();
    g_pending.clear();
    g_copy = std::move(f);
    return {};
}

void configure(int rank, int n_ranks, Level lvl) {
    g_rank = rank;
    g_n_ranks = n_ranks;
    g_level = lvl;
}
Level level() {
    return g_level;
}
int rank() {
    return g_rank;
}

void write_info(const std::string& message) {
    print(stdout, message + "\n");
}
void write_debug(const std::string& message) {
    print(stdout, fmt::format("{}debug: {}\n", rank_prefix(), message));
}
void write_warn(const std::string& message) {
    print(stderr, fmt::format("efdem: {}warning: {}\n", rank_prefix(), message));
}
void write_notice(const std::string& message) {
    print(stderr, fmt::format("efdem: {}\n", message));
}
void write_rank_error(const std::string& message) {
    print(stderr, fmt::format("efdem: [rank {} of {}] error: {}\n", g_rank, g_n_ranks, message));
}
void write_rank_warn(const std::string& message) {
    print(stderr, fmt::format("efdem: [rank {} of {}] warning: {}\n", g_rank, g_n_ranks, message));
}
void write_output(const std::string& text) {
    print(stdout, text);
}
void write_error(const std::string& message) {
    print(stderr, fmt::format("efdem: {}error: {}\n", rank_prefix(), message));
}

}  // namespace efdem::log
