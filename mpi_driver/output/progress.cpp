#include "mpi_driver/output/progress.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/log.hpp"

namespace efdem::mpi_driver {

Progress::Progress(double t_start, double t_end, double min_seconds)
    : t_start_(t_start), t_end_(t_end), min_seconds_(min_seconds) {}

double Progress::elapsed_seconds() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
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
    const double done = std::clamp((t_sim - t_start_) / (t_end_ - t_start_), 0.0, 1.0);
    const double shown = std::clamp((t_furthest_ - t_start_) / (t_end_ - t_start_), 0.0, 1.0);
    const double rate = wall > 0 ? particle_steps / wall : 0.0;
    const double work_done = expected_particle_steps_ > 0
                                 ? std::clamp(particle_steps / expected_particle_steps_, 0.0, 1.0)
                                 : done;
    const double eta = work_done > 0 ? wall * (1 - work_done) / work_done : 0.0;
    log::info(
        "t = {:9.3f} / {:g} ({:5.1f} %)  {:.3g} particle-steps/s  elapsed {}  ETA {}{}{}{}{}{}",
        t_sim, t_end_, 100 * shown, rate, format_duration(wall),
        work_done > 0 ? format_duration(eta) : "-",
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
