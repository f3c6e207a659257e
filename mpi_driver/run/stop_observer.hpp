#pragma once
/// \file
/// StopObserver: where a cpi run can stop. Between coarse steps (and before the warm-up) it
/// keeps the state as the stepper's resume point; if the ensemble has agreed to stop (a stop
/// signal), it ends the loop there with RunInterrupted. Plugged in before the checkpoint
/// observer, so that a periodic checkpoint sees every sample recorded.

#include "coarse/equation_free/projective/projective_run.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"

namespace efdem::mpi_driver {

class StopObserver final : public coarse::ProjectiveRunObserver {
  public:
    explicit StopObserver(EnsembleStepper& stepper) : stepper_(stepper) {}
    void between_steps(const coarse::ProjectiveRun& run) override;

  private:
    EnsembleStepper& stepper_;
};

}  // namespace efdem::mpi_driver
