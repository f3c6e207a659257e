#pragma once
/// \file
/// A run of the ensemble once it is set up (setup.hpp): every rank makes its realizations from
/// its beds (and puts a restart's states into them), the root makes the recorders and the
/// checkpoint writer and drives the mode's loop (driver.hpp, steady_driver.hpp) on the
/// EnsembleStepper while the other ranks serve it; a failure anywhere marks the run file
/// `failed: ...`. Returns the run's exit code (0, 3, 4; run_end.hpp).

#include <vector>

#include "core/param_table.hpp"
#include "dem/system.hpp"
#include "mpi_driver/checkpoint/restart_loader.hpp"
#include "mpi_driver/parallel/mpi_session.hpp"
#include "mpi_driver/run/run_settings.hpp"
#include "mpi_driver/run/setup.hpp"

namespace efdem::mpi_driver {

/// Collective. `restart`: the checkpoint to continue from (null: a new run).
int run_ensemble(const MpiSession& mpi, const ParamTable& table, const RunSettings& s,
                 std::vector<dem::System> systems, const RestartData* restart,
                 const SetupWall& wall);

}  // namespace efdem::mpi_driver
