#include "mpi_driver/run/progress_observer.hpp"

namespace efdem::mpi_driver {

void ProgressObserver::step_done(const coarse::ProjectiveRun& run, const coarse::ProjectiveStepRecord& rec) {
    if (stepper_.micro_time() > 0.0) {
        const double steps_per_time = stepper_.particle_steps() / stepper_.micro_time();
        const double dt_next = rec.dt > 0.0 ? rec.dt : rec.dt_requested;
        progress_.set_expected_particle_steps(stepper_.particle_steps() +
                                              steps_per_time * run.planned_micro_time(dt_next));
    }
    progress_.update(stepper_.time(), stepper_.particle_steps(), "", true);
}

}  // namespace efdem::mpi_driver
