#include "mpi_driver/run/settling_progress.hpp"

#include "core/log.hpp"
#include "mpi_driver/output/progress.hpp"

namespace efdem::mpi_driver {

dem::SettlingReport SettlingProgressLine::report() {
    return [this](const dem::SettlingProgress& p) { (*this)(p); };
}

void SettlingProgressLine::operator()(const dem::SettlingProgress& p) {
    const auto now = Clock::now();
    if (p.realization != realization_) {  // the first report of a realization starts its clock
        realization_ = p.realization;
        start_ = last_ = now;
    }
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (p.stage == dem::SettlingProgress::Stage::done) {
        const bool settled = p.ke_per_particle < p.ke_threshold;
        log::info(
            "settling realization {}: {} at t = {:.4g} ({} steps), KE/particle {:.2e} {} {:.2e}, "
            "{}",
            p.realization, settled ? "settled" : "stopped (bed.settle.max_time)", p.time, p.steps,
            p.ke_per_particle, settled ? "<" : ">=", p.ke_threshold, format_duration(elapsed));
        return;
    }
    if (std::chrono::duration<double>(now - last_).count() < min_seconds_) return;
    last_ = now;
    // What is measured against what: the stages before relaxing end at a set time; relaxing ends
    // when the kinetic energy falls below the threshold, and bed.settle.max_time is only the
    // limit at which it gives up.
    if (p.stage == dem::SettlingProgress::Stage::relaxing)
        log::info(
            "settling realization {}: relaxing until KE/particle < {:.2e}: now {:.2e} ({:.3g} x "
            "the threshold), t = {:.4g} (gives up at {:.4g}, bed.settle.max_time), {} steps, {}",
            p.realization, p.ke_threshold, p.ke_per_particle, p.ke_per_particle / p.ke_threshold,
            p.time, p.stage_end, p.steps, format_duration(elapsed));
    else
        log::info(
            "settling realization {}: {} stage, t = {:.4g} of {:.4g}, {} steps, KE/particle {:.2e} "
            "(then relaxing until below {:.2e}), {}",
            p.realization, dem::to_string(p.stage), p.time, p.stage_end, p.steps, p.ke_per_particle,
            p.ke_threshold, format_duration(elapsed));
}

}  // namespace efdem::mpi_driver
