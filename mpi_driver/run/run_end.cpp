#include "mpi_driver/run/run_end.hpp"

#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/shell_quote.hpp"
#include "mpi_driver/output/progress.hpp"
#include "mpi_driver/parallel/stop_signal.hpp"

namespace efdem::mpi_driver {

int report_end(const RunSummary& summary, const RunSettings& s, const ParamTable& table,
               int ranks) {
    // A restarted run's loop counts the processes before it (their wall is not in this one's).
    const double resumed = summary.resumed_wall_seconds;
    const std::string loop =
        resumed == 0.0 ? fmt::format("{} the run", format_duration(summary.wall_seconds))
        : std::isfinite(resumed)
            ? fmt::format("{} the run here; {} with the processes it resumed from",
                          format_duration(summary.wall_seconds - resumed),
                          format_duration(summary.wall_seconds))
            : fmt::format("{} the run here; the processes it resumed from unknown",
                          format_duration(summary.wall_seconds));
    log::info(
        "{}: simulated {:.6g} time units ({:.6g} by the DEM) in {} wall ({} settling the beds, "
        "{}), {:.3e} particle-steps",
        summary.end_status, summary.simulated_time, summary.dem_time,
        format_duration(summary.total_wall_seconds), format_duration(summary.settling_wall_seconds),
        loop, summary.particle_steps);
    if (summary.stop_signal == 0) return summary.unconverged ? kExitRuntimeFailure : kExitOk;
    const std::string signal = signal_name(summary.stop_signal);
    if (summary.solve_interrupted) {
        log::notice(
            "stopped by {}; the iterates so far and the best one are in {}/{}.h5 ({} cannot be "
            "continued from a checkpoint{})",
            signal, s.output.directory.string(), s.output.prefix,
            s.is_steady() ? fmt::format("mode = {}", s.mode_name())
                          : std::string("the steady solve of cpi.hand_off = steady"),
            s.is_steady() ? "" : "; restarting the cpi run's last checkpoint redoes it");
    } else if (summary.checkpoint.empty()) {
        log::notice("stopped by {}; nothing could be saved (no HDF5)", signal);
    } else {
        // Every argument quoted for a POSIX shell: the line is meant to be pasted.
        std::string command =
            fmt::format("mpirun -n {} efdem {}", ranks, shell_quote(table.file()));
        for (const auto& o : table.overrides()) command += fmt::format(" {}", shell_quote(o));
        command += fmt::format(" {}", shell_quote(fmt::format("restart={}", summary.checkpoint)));
        log::notice("stopped by {}: checkpoint {} (t = {:.6g}); continue with: {}", signal,
                    summary.checkpoint, summary.checkpoint_time, command);
    }
    return kExitInterrupted;
}

}  // namespace efdem::mpi_driver
