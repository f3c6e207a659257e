#pragma once
/// \file
/// The answers of the commands that run nothing: --help, --version, --list-effects (with the
/// keys each effect lets a run change), --list-keys (the keys a scene's set-up read). Printed
/// by the root (log::output).

#include "core/param_table.hpp"
#include "mpi_driver/run/run_options.hpp"

namespace efdem::mpi_driver {

/// --help, --version or --list-effects: true when `action` is one of them (and printed it).
bool print_listing(RunOptions::Action action);

/// --list-keys: every key the scene's set-up read, with what it accepts and its default (TSV).
void print_keys(const ParamTable& table);

}  // namespace efdem::mpi_driver
