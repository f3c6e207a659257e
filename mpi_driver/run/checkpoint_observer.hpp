#pragma once
/// \file
/// CheckpointObserver: the checkpoint cadence of a cpi run: a whole-ensemble checkpoint every
/// `interval` coarse steps, written between two steps (nothing of a burst is pending there),
/// with the run loop's state so that a restart continues the run exactly; inside a warm-up by
/// time, every `interval` pieces of one burst length (so that a job shorter than its warm-up
/// still progresses from one requeue to the next).

#include <filesystem>
#include <string>

#include "coarse/equation_free/projective/projective_run.hpp"
#include "mpi_driver/ensemble/ensemble_stepper.hpp"
#include "mpi_driver/output/progress.hpp"

namespace efdem::mpi_driver {

/// "PATH (t = T, 1.25 MB in 0.04 s" without the closing bracket: what a progress line says of
/// the checkpoint `stepper` wrote last (its size as the root sees it).
std::string describe_checkpoint(const std::filesystem::path& path, const EnsembleStepper& stepper);

class CheckpointObserver final : public coarse::ProjectiveRunObserver {
  public:
    /// `interval` > 0 coarse steps; `last`: the coarse step the newest checkpoint was written
    /// after (that of the checkpoint a restarted run resumed from, so it is not written again).
    /// Each checkpoint is said on the next progress line (Progress::note_checkpoint).
    CheckpointObserver(EnsembleStepper& stepper, Progress& progress, long interval, long last)
        : stepper_(stepper), progress_(progress), interval_(interval), last_(last) {}
    void between_steps(const coarse::ProjectiveRun& run) override;

  private:
    EnsembleStepper& stepper_;
    Progress& progress_;
    long interval_;
    long last_;
    long warmup_pieces_ = 0;  ///< warm-up pieces seen by this process
};

}  // namespace efdem::mpi_driver
