#pragma once
/// \file
/// Stop signals: SIGTERM, SIGINT and SIGUSR1 (what Slurm sends at the time limit, Ctrl-C, and
/// `sbatch --signal=B:USR1@...` forwarded by mpirun) ask the run to stop at its next safe point.
///
/// The handler only records the signal (async-signal-safe); a realization looks for it every
/// few DEM steps and gives its sample up (Realization::advance_unless_stopped), and the ensemble
/// agrees on it at every sample (EnsembleStepper: one MPI_Allreduce), so a signal that reaches
/// one rank stops them all at the same sample, where the run writes a checkpoint and ends with
/// kExitInterrupted.
/// A second signal ends the process at once (exit 128 + signal number), without a checkpoint:
/// the checkpoints already on disk are untouched (their writing is crash-safe). A repeat within
/// 2 s of the first counts as the same request delivered twice (Slurm signals every process of
/// a job step and mpirun forwards the same signal once more).

#include <stdexcept>
#include <string>

namespace efdem::mpi_driver {

/// Installs the handlers (once per process; later calls do nothing).
void install_stop_signal_handlers();
/// The first stop signal received by this process (0: none).
int stop_signal_received();
/// "SIGTERM", "SIGINT", "SIGUSR1" or "signal N".
std::string signal_name(int signal);

/// Thrown on the root by EnsembleStepper::run() (and by the run loop's stop observer) when the
/// ensemble agreed to stop: the burst in progress is cut short, so the caller must not use it.
/// The driver catches it, writes the checkpoint of the last safe point and ends the run.
class RunInterrupted : public std::runtime_error {
  public:
    RunInterrupted(int signal, double time);
    int signal() const { return signal_; }
    double time() const { return time_; }  ///< the sample at which the ensemble stopped

  private:
    int signal_;
    double time_;
};

}  // namespace efdem::mpi_driver
