#include "mpi_driver/run/checkpoint_observer.hpp"

#include "core/contracts.hpp"
#include "core/log.hpp"

namespace efdem::mpi_driver {

void CheckpointObserver::between_steps(const coarse::ProjectiveRun& run) {
    EFDEM_EXPECTS(interval_ > 0);
    const long steps = run.state().coarse_steps;
    if (steps == last_ || steps % interval_ != 0) return;
    const auto path = stepper_.checkpoint(steps, run.state());
    log::info("checkpoint {} (t = {:.6g}, after coarse step {})", path.string(), stepper_.time(),
              steps);
    last_ = steps;
}

}  // namespace efdem::mpi_driver
