#pragma once
/// \file
/// Advice a run prints once at its start: what its mode cannot deliver on its scene, measured
/// (the run goes on; a contradiction in the input is an error elsewhere, not advice).

#include <string>
#include <vector>

#include "dem/system.hpp"

namespace efdem::mpi_driver {

/// The warnings for a run of `system` (any realization: the scene is shared); `cpi`: a cpi run,
/// `jumps_end`: one whose jumps end before its end (cpi.jump_until). A cpi run at a U_s that
/// some species does not fluidize on its own, jumping to its end, is told that CPI keeps beds
/// moving, so an end state in which beds come to rest is not what it computes.
std::vector<std::string> run_advice(bool cpi, bool jumps_end, const dem::System& system);

}  // namespace efdem::mpi_driver
