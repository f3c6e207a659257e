#include "mpi_driver/output/progress.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/log.hpp"

namespace efdem::mpi_driver {

Progress::Progress(double t_start, double t_end, double min_seconds)
    : t_start_(t_start), t_end_(t_end), min_seconds_(min_seconds) {}

double Progress::elapsed_seconds() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
}

void Progress::resume(double t_sim, double particle_steps) {
    t_resumed_ = t_sim;
    steps_resumed_ = particle_steps;
    t_furthest_ = std::max(t_furthest_, t_sim);
}

Progress::Figures Progress::figures(double t_sim, double particle_steps, double wall) const {
    Figures f;
    f.shown = std::clamp((std::max(t_furthest_, t_sim) - t_start_) / (t_end_ - t_start_), 0.0, 1.0);
    const double steps = particle_steps - steps_resumed_;  // this process's work
    f.rate = wall > 0 ? steps / wall : 0.0;
    f.eta = std::numeric_limits<double>::quiet_NaN();
    if (expected_particle_steps_ > 0) {  // the work left, at this process's rate
        if (steps > 0)
            f.eta = wall * std::max(expected_particle_steps_ - particle_steps, 0.0) / steps;
    } else if (t_sim > t_resumed_) {  // the simulated time left, at this process's pace
        f.eta = wall * std::max(t_end_ - t_sim, 0.0) / (t_sim - t_resumed_);
    }
    return f;
}

void Progress::update(double t_sim, double particle_steps, const std::string& extra, bool force) {
    // A rejected jump (or a steady solve's next evaluation) sends the clock back: the share
    // shown is the furthest reached, and the line says that a stretch is being redone.
    const bool redoing = t_sim < t_furthest_;
    t_furthest_ = std::max(t_furthest_, t_sim);
    const auto now = Clock::now();
    if (!force && last_ != Clock::time_point::min() &&
        std::chrono::duration<double>(now - last_).count() < min_seconds_)
        return;
    last_ = now;
    const double wall = elapsed_seconds();
    const Figures f = figures(t_sim, particle_steps, wall);
    log::info(
        "t = {:9.3f} / {:g} ({:5.1f} %)  {:.3g} particle-steps/s  elapsed {}  ETA {}{}{}{}{}{}",
        t_sim, t_end_, 100 * f.shown, f.rate, format_duration(wall), format_duration(f.eta),
        redoing ? fmt::format("  (redoing up to t = {:.6g})", t_furthest_) : std::string(),
        extra.empty() ? "" : "  ", extra, checkpoint_.empty() ? "" : "  ", checkpoint_);
    checkpoint_.clear();
}

std::string format_duration(double s) {
    if (!std::isfinite(s) || s < 0) return "-";
    const long total = std::lround(s);
    if (total >= 3600) return fmt::format("{}h{:02d}m", total / 3600, (total % 3600) / 60);
    if (total >= 60) return fmt::format("{}m{:02d}s", total / 60, total % 60);
    return fmt::format("{}s", total);
}

}  // namespace efdem::mpi_driver
