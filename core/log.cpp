#include "core/log.hpp"

#include <cstdio>

namespace efdem::log {

namespace {
int g_rank = 0;
int g_n_ranks = 1;
Level g_level = Level::info;

std::string rank_prefix() {
    return g_n_ranks > 1 ? fmt::format("[rank {}] ", g_rank) : "";
}
}  // namespace

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
    std::fprintf(stdout, "%s\n", message.c_str());
    std::fflush(stdout);
}
void write_debug(const std::string& message) {
    std::fprintf(stdout, "%sdebug: %s\n", rank_prefix().c_str(), message.c_str());
    std::fflush(stdout);
}
void write_warn(const std::string& message) {
    std::fprintf(stderr, "efdem: %swarning: %s\n", rank_prefix().c_str(), message.c_str());
    std::fflush(stderr);
}
void write_notice(const std::string& message) {
    std::fprintf(stderr, "efdem: %s\n", message.c_str());
    std::fflush(stderr);
}
void write_rank_error(const std::string& message) {
    std::fprintf(stderr, "efdem: [rank %d of %d] error: %s\n", g_rank, g_n_ranks, message.c_str());
    std::fflush(stderr);
}
void write_rank_warn(const std::string& message) {
    std::fprintf(stderr, "efdem: [rank %d of %d] warning: %s\n", g_rank, g_n_ranks,
                 message.c_str());
    std::fflush(stderr);
}
void write_output(const std::string& text) {
    std::fputs(text.c_str(), stdout);
    std::fflush(stdout);
}
void write_error(const std::string& message) {
    std::fprintf(stderr, "efdem: %serror: %s\n", rank_prefix().c_str(), message.c_str());
    std::fflush(stderr);
}

}  // namespace efdem::log
