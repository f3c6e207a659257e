#pragma once
/// \file
/// Progress: the root's one-line report per coarse step or sampling interval: simulated time,
/// fraction done, particle-steps per wall second, and the estimated time left.

#include <chrono>
#include <string>

namespace efdem::mpi_driver {

class Progress {
public:
    /// `t_start`, `t_end`: the simulated span of the run; `min_seconds`: least wall time
    /// between two lines (0 prints every call).
    Progress(double t_start, double t_end, double min_seconds);
    /// Prints a line if due (or `force`); `particle_steps` is the running total.
    void update(double t_sim, double particle_steps, const std::string& extra, bool force = false);
    double elapsed_seconds() const;

private:
    using Clock = std::chrono::steady_clock;
    double t_start_, t_end_, min_seconds_;
    Clock::time_point start_ = Clock::now();
    Clock::time_point last_ = Clock::time_point::min();
};

/// "1h02m", "3m20s", "12s".
std::string format_duration(double seconds);

}  // namespace efdem::mpi_driver
