#pragma once
/// \file
/// FailurePolicy: what the ensemble does when one realization fails (a non-finite position, the
/// watchdog, an I/O error of its own output). Scene keys ensemble.on_failure and
/// ensemble.max_failures (run_settings.hpp).
///
/// * abort (default): every rank stops (exit 3), the run file is marked failed;
/// * drop: the realization leaves the ensemble: from then on it is not advanced, and the means
///   (and, in cpi, the slopes and their spread) are over the others; the run file records
///   the R of every sample. In cpi the coarse step in progress is redone from where it began
///   (the resume point), so every sample of a step has the same realizations.
/// * replace (cpi only): the realization is rebuilt where the interrupted coarse step began from
///   a healthy one's state, given a fresh lifting stream of its own and lifted at once to the
///   ensemble's coarse state there; the step is redone. In a direct run a copy would follow its
///   donor's trajectory (the DEM is deterministic) and correlate the ensemble, so direct runs
///   can only drop.
///
/// More than max_failures failures in a run, or too few realizations left (2 where the run
/// measures the spread of slopes, else 1), end it as abort does.

namespace efdem::mpi_driver {

struct FailurePolicy {
    enum class Action { abort, drop, replace } action = Action::abort;
    long max_failures = 0;  ///< failures a run survives (drop/replace)
    int min_active = 1;     ///< realizations that must remain
};

}  // namespace efdem::mpi_driver
