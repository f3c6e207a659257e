#include "mpi_driver/run/progress_observer.hpp"

#include <string>

#include <fmt/format.h>

namespace efdem::mpi_driver {

void ProgressObserver::step_done(const coarse::ProjectiveRun& run,
                                 const coarse::ProjectiveStepRecord& rec) {
    if (stepper_.micro_time() > 0.0) {
        const double steps_per_time = stepper_.particle_steps() / stepper_.micro_time();
        const double dt_next = rec.dt > 0.0 ? rec.dt : rec.dt_requested;
        progress_.set_expected_particle_steps(stepper_.particle_steps() +
                                              steps_per_time * run.planned_micro_time(dt_next));
    }
    // Adaptive CPI: what the controller just did, on the progress line.
    std::string note;
    if (const coarse::ControllerRecord& c = rec.controller; c.adaptive && rec.lifted)
        note = fmt::format("DT {:.3g} {}: error {:.2f} of tolerance", rec.dt,
                           c.accepted ? "kept" : "rejected", c.error() / c.tolerance);
    else if (c.adaptive && rec.status == coarse::StepStatus::burst_only &&
             c.limited_by != coarse::DtLimit::none)
        note = "no jump: " + std::string(coarse::to_string(c.limited_by));
    progress_.update(stepper_.time(), stepper_.particle_steps(), note, true);
}

}  // namespace efdem::mpi_driver
