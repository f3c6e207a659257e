#pragma once
/// \file
/// StepReportObserver: reports every coarse step of a cpi run: the step record and what lifting
/// did go to the run's recorders (HDF5, CSV), and one line goes to the log.

#include "coarse/equation_free/projective/projective_run.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"
#include "mpi_driver/output/run_recorder.hpp"

namespace efdem::mpi_driver {

class StepReportObserver final : public coarse::ProjectiveRunObserver {
  public:
    /// `recorder` may be null (log line only).
    StepReportObserver(const EnsembleStepper& stepper, RunRecorder* recorder)
        : stepper_(stepper), recorder_(recorder) {}
    void step_done(const coarse::ProjectiveRun& run,
                   const coarse::ProjectiveStepRecord& record) override;

  private:
    const EnsembleStepper& stepper_;
    RunRecorder* recorder_;
};

/// "coarse step n: burst t0..t1, DT = ..., projected, k labels changed, ..." (the log line).
std::string describe_step(long n, const coarse::ProjectiveStepRecord& record,
                          const LiftRecord& lift);

}  // namespace efdem::mpi_driver
