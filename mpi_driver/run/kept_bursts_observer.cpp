#include "mpi_driver/run/kept_bursts_observer.hpp"

namespace efdem::mpi_driver {

void KeptBurstsObserver::step_done(const coarse::ProjectiveRun& run,
                                   const coarse::ProjectiveStepRecord& rec) {
    (void)run;
    const bool kept =
        rec.status == coarse::StepStatus::projected || rec.status == coarse::StepStatus::burst_only;
    if (!kept || rec.x_end.size() == 0) return;
    times_.push_back(rec.t_end);
    states_.push_back(rec.x_end);
}

}  // namespace efdem::mpi_driver
