#pragma once
/// \file
/// Progress: the root's one-line report per coarse step or sampling interval: simulated time,
/// fraction done, particle-steps per wall second, and the estimated time left.

#include <chrono>
#include <limits>
#include <string>
#include <utility>

namespace efdem::mpi_driver {

class Progress {
  public:
    /// `t_start`, `t_end`: the simulated span of the run; `min_seconds`: least wall time
    /// between two lines (0 prints every call).
    Progress(double t_start, double t_end, double min_seconds);
    /// Prints a line if due (or `force`); `particle_steps` is the running total.
    void update(double t_sim, double particle_steps, const std::string& extra, bool force = false);
    /// The particle-steps the whole run is expected to take, when the simulated time is not a
    /// measure of the work (coarse projective runs: a jump advances time for free). The time
    /// left is then estimated from the particle-steps left; 0 (the default) estimates it from
    /// the simulated time left.
    void set_expected_particle_steps(double total) { expected_particle_steps_ = total; }
    double elapsed_seconds() const;
    /// A restarted run: the simulated time and the particle-steps it resumes with are not this
    /// process's work, so the rate and the time left count from them (without this, a run
    /// restarted at 40 % showed a rate of 7e9 particle-steps/s and 3 s left).
    void resume(double t_sim, double particle_steps);
    /// What a line shows, given the wall time of this process so far.
    struct Figures {
        double shown = 0.0;  ///< fraction of the span reached (the furthest time)
        double rate = 0.0;   ///< particle-steps per wall second since the start or the resume
        double eta = 0.0;    ///< wall seconds left; NaN while nothing is done yet
    };
    Figures figures(double t_sim, double particle_steps, double wall) const;
    /// A checkpoint was written (`what`: "checkpoint FILE (t = ...)"): said at the end of the
    /// next progress line, not on a line of its own, so that a job's log holds no more
    /// checkpoint lines than progress lines (checkpoint.interval = 1 in a direct run would
    /// otherwise print one per sample). A later checkpoint replaces one not said yet: the line
    /// names the newest.
    void note_checkpoint(std::string what) { checkpoint_ = std::move(what); }

  private:
    using Clock = std::chrono::steady_clock;
    double t_start_, t_end_, min_seconds_;
    double expected_particle_steps_ = 0.0;
    double t_resumed_ = t_start_;  ///< where this process's work started
    double steps_resumed_ = 0.0;   ///< the particle-steps done before it
    Clock::time_point start_ = Clock::now();
    Clock::time_point last_ = Clock::time_point::min();
    double t_furthest_ = -std::numeric_limits<double>::infinity();  ///< the latest time reached
    std::string checkpoint_;  ///< the newest checkpoint not yet said (empty: none)
};

/// "1h02m", "3m20s", "12s".
std::string format_duration(double seconds);

}  // namespace efdem::mpi_driver
