#pragma once
/// \file
/// The report of `efdem --check`: what a scene switches on and everything derived from it.

#include <string>

#include "core/param_table.hpp"
#include "dem/system.hpp"
#include "mpi_driver/run/run_settings.hpp"

namespace efdem::mpi_driver {

/// Active effects in order with their derived numbers (eta_n per pair, t_c, ...), dt/t_c, what
/// was built and what was not, and every parameter with its value and origin.
std::string check_report(const ParamTable& table, const RunSettings& settings,
                         const dem::System& realization0, int n_ranks);

}  // namespace efdem::mpi_driver
