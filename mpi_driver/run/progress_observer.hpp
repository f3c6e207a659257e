#pragma once
/// \file
/// ProgressObserver: after every coarse step, the progress line with the time left estimated
/// from the DEM work the run still needs (a jump advances simulated time for free, so the
/// simulated time left is no measure of the work left).

#include "coarse/equation_free/projective/projective_run.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"
#include "mpi_driver/output/progress.hpp"

namespace efdem::mpi_driver {

class ProgressObserver final : public coarse::ProjectiveRunObserver {
  public:
    ProgressObserver(const EnsembleStepper& stepper, Progress& progress)
        : stepper_(stepper), progress_(progress) {}
    void step_done(const coarse::ProjectiveRun& run,
                   const coarse::ProjectiveStepRecord& record) override;

  private:
    const EnsembleStepper& stepper_;
    Progress& progress_;
};

}  // namespace efdem::mpi_driver
