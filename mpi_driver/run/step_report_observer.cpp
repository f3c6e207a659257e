#include "mpi_driver/run/step_report_observer.hpp"

#include <cmath>

#include <fmt/format.h>

#include "coarse/equation_free/projective/step_size_controller.hpp"  // error_parts
#include "core/log.hpp"

namespace efdem::mpi_driver {

std::string describe_step(long n, const coarse::ProjectiveStepRecord& r, const LiftRecord& lift) {
    long changed = 0;
    for (long c : lift.changed) changed += c;
    std::string s = fmt::format("coarse step {}: burst {:.4g}..{:.4g}", n, r.t_start,
                                r.t_start + r.burst_length);
    if (std::isfinite(r.period)) s += fmt::format(", period T = {:.4g}", r.period);
    s += fmt::format(", DT = {:.4g}, {}", r.dt, coarse::to_string(r.status));
    if (r.lifted) s += fmt::format(", {} {}", changed, lift.changed_what);
    // The lift's own error in X (the burst after the jump does not measure it).
    if (r.lifted && std::isfinite(lift.error))
        s += fmt::format(", lift error {:.3g} d_p", lift.error);
    if (r.repair.changed())
        s += fmt::format(", repaired (max {:.3g} d_p)", r.repair.max_adjustment);
    if (r.slope_standard_error.size() > 0)
        s += fmt::format(", slope s.e. max {:.3g}", r.max_slope_standard_error());
    if (const coarse::ControllerRecord& c = r.controller; c.adaptive && r.lifted)
        s += fmt::format(", error {:.3g} d_p = {:.2f} of tolerance ({}), DT set by {}", c.error(),
                         c.error() / c.tolerance,
                         coarse::error_parts(c.statistical, c.truncation, c.lift),
                         coarse::to_string(c.limited_by));
    else if (c.active && r.lifted)
        s += fmt::format(", error estimate {:.3g} d_p ({})", c.error(),
                         coarse::error_parts(c.statistical, c.truncation, c.lift));
    if (const coarse::ControllerRecord& c = r.controller;
        c.active && r.lifted && c.slope_source == coarse::SlopeSource::pooled)
        s += fmt::format(
            ", slope pooled over {} burst{} (its own statistical error {:.3g}; one burst's "
            "{:.3g}, the whole pool's {:.3g})",
            c.pooled_bursts, c.pooled_bursts == 1 ? "" : "s", c.statistical_jump,
            c.statistical_burst, c.statistical_pool);
    if (!r.message.empty()) s += " [" + r.message + "]";
    return s;
}

void StepReportObserver::step_done(const coarse::ProjectiveRun& run,
                                   const coarse::ProjectiveStepRecord& rec) {
    // A failed lift is recorded too (what it did, its error, why each realization was not
    // lifted), although the ensemble went back to the state before the jump.
    const bool attempted = rec.lifted || rec.status == coarse::StepStatus::lift_failed;
    const LiftRecord lift = attempted ? stepper_.last_lift() : LiftRecord{};
    if (recorder_) recorder_->coarse_step(rec, lift);
    log::info("{}", describe_step(run.state().coarse_steps, rec, lift));
}

}  // namespace efdem::mpi_driver
