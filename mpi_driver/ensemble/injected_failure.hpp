#pragma once
/// \file
/// InjectedFailure: a test-only fault (scene keys debug.fail_realization, debug.fail_time) that
/// makes one realization fail as a blown-up one would, to test how a run ends.

namespace efdem::mpi_driver {

/// Realization `realization` fails at the first sample at or after `time` (-1: none); with
/// `keep_stage` instead when the ensemble first keeps its state (between coarse steps, before a
/// jump) at or after `time`: the rank that owns it cannot copy its state, a local failure
/// inside a stage every rank runs, which the ranks must agree on.
struct InjectedFailure {
    long realization = -1;
    double time = 0;
    bool keep_stage = false;
};

}  // namespace efdem::mpi_driver
