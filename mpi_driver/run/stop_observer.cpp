#include "mpi_driver/run/stop_observer.hpp"

#include "mpi_driver/parallel/stop_signal.hpp"

namespace efdem::mpi_driver {

void StopObserver::between_steps(const coarse::ProjectiveRun& run) {
    stepper_.mark_resume_point(run.state());
    if (stepper_.interrupted()) throw RunInterrupted(stepper_.interrupted(), stepper_.time());
}

}  // namespace efdem::mpi_driver
