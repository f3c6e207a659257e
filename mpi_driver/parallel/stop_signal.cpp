#include "mpi_driver/parallel/stop_signal.hpp"

#include <unistd.h>
#include <csignal>
#include <cstring>
#include <ctime>

#include <fmt/format.h>

namespace efdem::mpi_driver {

namespace {
volatile std::sig_atomic_t g_first_signal = 0;
bool g_installed = false;
timespec g_first_time{};

/// Seconds within which a repeated signal counts as the same request delivered twice (a
/// batch system signals every process of a job, and mpirun forwards the same signal again).
constexpr double kDuplicateWindow = 2.0;

void on_stop_signal(int signal) {
    timespec now{};
    clock_gettime(CLOCK_MONOTONIC, &now);  // async-signal-safe
    if (g_first_signal != 0) {
        const double since = static_cast<double>(now.tv_sec - g_first_time.tv_sec) +
                             1e-9 * static_cast<double>(now.tv_nsec - g_first_time.tv_nsec);
        if (since < kDuplicateWindow) return;
        // Second signal: end now. Only async-signal-safe calls here (write, _exit).
        static const char message[] =
            "efdem: second stop signal: ending at once, without a checkpoint\n";
        [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, message, sizeof message - 1);
        ::_exit(128 + signal);
    }
    g_first_time = now;
    g_first_signal = signal;
}
}  // namespace

void install_stop_signal_handlers() {
    if (g_installed) return;
    g_installed = true;
    struct sigaction action;
    std::memset(&action, 0, sizeof action);
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;  // interrupted system calls (file writes) resume
    for (const int s : {SIGTERM, SIGINT, SIGUSR1}) sigaction(s, &action, nullptr);
}

int stop_signal_received() {
    return static_cast<int>(g_first_signal);
}

RunInterrupted::RunInterrupted(int signal, double time)
    : std::runtime_error(fmt::format("stopped by {} at t = {:.6g}", signal_name(signal), time)),
      signal_(signal),
      time_(time) {}

std::string signal_name(int signal) {
    switch (signal) {
        case SIGTERM:
            return "SIGTERM";
        case SIGINT:
            return "SIGINT";
        case SIGUSR1:
            return "SIGUSR1";
        default:
            return fmt::format("signal {}", signal);
    }
}

}  // namespace efdem::mpi_driver
