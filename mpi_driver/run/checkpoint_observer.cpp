#include "mpi_driver/run/checkpoint_observer.hpp"

#include <fmt/format.h>

#include "core/contracts.hpp"

namespace efdem::mpi_driver {

void CheckpointObserver::between_steps(const coarse::ProjectiveRun& run) {
    EFDEM_EXPECTS(interval_ > 0);
    if (!run.state().warmed_up) {
        // Inside the warm-up (pieces of one burst length): every checkpoint.interval pieces,
        // under sequence 0 (each replaces the last: the newest is the only one worth keeping).
        if (run.state().warmup_done == 0 || ++warmup_pieces_ % interval_ != 0) return;
        const auto path = stepper_.checkpoint(0, run.state());
        progress_.note_checkpoint(
            fmt::format("checkpoint {} (t = {:.6g}, {:.6g} time units into "
                        "the warm-up)",
                        path.string(), stepper_.time(), run.state().warmup_done));
        return;
    }
    const long steps = run.state().coarse_steps;
    if (steps == last_ || steps % interval_ != 0) return;
    const auto path = stepper_.checkpoint(steps, run.state());
    progress_.note_checkpoint(fmt::format("checkpoint {} (t = {:.6g}, after coarse step {})",
                                          path.string(), stepper_.time(), steps));
    last_ = steps;
}

}  // namespace efdem::mpi_driver
