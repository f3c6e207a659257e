#pragma once
/// \file
/// The set-up of a run, collective: every rank reads the same scene (scene_input.hpp), the run
/// settings, and builds (and settles) its realizations' beds; the root takes the prefix's lock
/// (output_lock.hpp), checks that the output may be written (output_guard.hpp) and, with
/// output.overwrite, deletes the earlier run's files. Each stage ends in one agreement
/// (agree_on_failure), so every rank stops together and the root prints one message: exit code 2
/// for bad input, 3 for a failure.

#include <chrono>
#include <optional>
#include <vector>

#include "core/param_table.hpp"
#include "dem/system.hpp"
#include "mpi_driver/output/run_recorder.hpp"
#include "mpi_driver/parallel/mpi_broadcast.hpp"
#include "mpi_driver/parallel/mpi_session.hpp"
#include "mpi_driver/run/output_lock.hpp"
#include "mpi_driver/run/run_options.hpp"
#include "mpi_driver/run/run_settings.hpp"

namespace efdem::mpi_driver {

/// The root's wall clock outside the run loop: since start-up, and the set-up's settling.
struct SetupWall {
    using Clock = std::chrono::steady_clock;
    Clock::time_point start = Clock::now();
    double settling_seconds = 0;

    static double seconds_since(Clock::time_point t) {
        return std::chrono::duration<double>(Clock::now() - t).count();
    }
    void fill(RunSummary& s) const {
        s.settling_wall_seconds = settling_seconds;
        s.total_wall_seconds = seconds_since(start);
    }
};

/// What the set-up made. `check`: --check or --list-keys (one realization, nothing settled,
/// nothing written).
struct SetUp {
    std::optional<ParamTable> table;
    std::optional<RunSettings> settings;
    std::vector<dem::System> systems;  ///< this rank's realizations' beds
    /// With bed.write (a new run, not --check): this rank's beds as built and settled, in the
    /// order of `systems`, until set_up has written them.
    std::vector<dem::Particles> beds;
    bool check = false;
    int ranks = 1;                   ///< the ranks the run is for (--ranks=N with --check)
    std::optional<OutputLock> lock;  ///< the root's, for the whole run (not with --check)
};

/// Collective: reads the scene of `options`, builds this rank's beds into `out` and records the
/// settling's wall time in `wall`; with bed.write, once the output guard has passed, every rank
/// writes its realizations' beds (dem::write_lammps_data, one file each). The agreement's exit
/// code is 0 when `out` is ready.
Agreement set_up(const MpiSession& mpi, const RunOptions& options, SetupWall& wall, SetUp& out);

/// Root, once the run can start (set up, and a restart's states restored): the run's log,
/// PREFIX_log.txt, from here on, with everything printed so far (log::open_copy). `restart`:
/// the checkpoint continued (empty: a new run). A set-up or restart that fails leaves no log.
void open_run_log(const MpiSession& mpi, const ParamTable& table, const RunSettings& settings,
                  const std::string& restart);

}  // namespace efdem::mpi_driver
