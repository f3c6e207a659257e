#pragma once
/// \file
/// InjectedFailure: a test-only fault (scene keys debug.fail_realization, debug.fail_time) that
/// makes one realization fail as a blown-up one would, to test how a run ends.

namespace efdem::mpi_driver {

/// Realization `realization` fails at the first sample at or after `time` (-1: none).
struct InjectedFailure {
    long realization = -1;
    double time = 0;
};

}  // namespace efdem::mpi_driver
