#pragma once
/// \file
/// How a run that got going ends on the root: the closing line (status, simulated and DEM time,
/// wall time of the settling and of the run, particle-steps) and, for a run a signal stopped,
/// the one line that says where it was saved and the command that continues it. Returns the
/// exit code: 0, 3 (a steady solve that did not converge) or 4 (stopped).

#include "core/param_table.hpp"
#include "mpi_driver/output/run_recorder.hpp"
#include "mpi_driver/run/run_settings.hpp"

namespace efdem::mpi_driver {

/// `ranks`: of the run (the continue command repeats it).
int report_end(const RunSummary& summary, const RunSettings& s, const ParamTable& table, int ranks);

}  // namespace efdem::mpi_driver
