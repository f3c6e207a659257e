#include "mpi_driver/run/checkpoint_observer.hpp"

#include <fmt/format.h>

#include "core/contracts.hpp"

namespace efdem::mpi_driver {

std::string describe_checkpoint(const std::filesystem::path& path, const EnsembleStepper& stepper) {
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(path, ec);
    return fmt::format("{} (t = {:.6g}, {:.3g} MB in {:.2g} s", path.string(), stepper.time(),
                       ec ? 0.0 : static_cast<double>(bytes) / 1e6,
                       stepper.last_checkpoint_seconds());
}

void CheckpointObserver::between_steps(const coarse::ProjectiveRun& run) {
    EFDEM_EXPECTS(interval_ > 0);
    if (!run.state().warmed_up) {
        // Inside the warm-up (pieces of one burst length): every checkpoint.interval pieces,
        // under sequence 0 (each replaces the last: the newest is the only one worth keeping).
        if (run.state().warmup_done == 0 || ++warmup_pieces_ % interval_ != 0) return;
        const auto path = stepper_.checkpoint(0, run.state());
        progress_.note_checkpoint(fmt::format("checkpoint {}, {:.6g} time units into the warm-up)",
                                              describe_checkpoint(path, stepper_),
                                              run.state().warmup_done));
        return;
    }
    const long steps = run.state().coarse_steps;
    if (steps == last_ || steps % interval_ != 0) return;
    const auto path = stepper_.checkpoint(steps, run.state());
    progress_.note_checkpoint(fmt::format("checkpoint {}, after coarse step {})",
                                          describe_checkpoint(path, stepper_), steps));
    last_ = steps;
}

}  // namespace efdem::mpi_driver
