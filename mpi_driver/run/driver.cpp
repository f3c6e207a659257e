#include "mpi_driver/run/driver.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include <fmt/format.h>

#include "coarse/demixing/monotone_repair.hpp"
#include "coarse/equation_free/period_projective_euler.hpp"
#include "coarse/equation_free/projective_forward_euler.hpp"
#include "coarse/equation_free/projective_integrator.hpp"
#include "core/log.hpp"

namespace efdem::mpi_driver {

namespace {
constexpr double kTimeTolerance = 1e-9;

/// Consecutive outer steps without a jump after which a cpi run stops (the run would silently
/// have become a direct run).
constexpr int kMaxStepsWithoutProgress = 3;

std::unique_ptr<coarse::ProjectiveIntegrator> make_integrator(const RunSettings& s, coarse::RepairHook hook) {
    const CpiSettings& c = s.cpi;
    if (c.projection == CpiSettings::Projection::fixed) {
        coarse::ProjectiveEulerSettings e;
        e.healing = c.healing;
        e.window = c.window;
        e.dt = c.dt;
        e.stability_policy = c.stability;
        return std::make_unique<coarse::ProjectiveForwardEuler>(e, std::move(hook));
    }
    coarse::PeriodProjectiveEulerSettings e;
    e.healing = c.healing;
    e.window = c.window;
    e.periods_per_step = c.periods;
    e.max_extension = c.max_extension;
    // Extensions must land on samples: 5 time units rounded to whole sampling intervals.
    e.extension_step = std::max(1.0, std::round(5.0 / s.observe.interval)) * s.observe.interval;
    e.stability_policy = c.stability;
    return std::make_unique<coarse::PeriodProjectiveEuler>(e, std::move(hook));
}

std::string describe_step(long n, const coarse::ProjectiveStepRecord& r, const LiftRecord& lift) {
    long changed = 0;
    for (long c : lift.changed) changed += c;
    std::string s = fmt::format("coarse step {}: burst {:.4g}..{:.4g}", n, r.t_start, r.t_start + r.burst_length);
    if (std::isfinite(r.period)) s += fmt::format(", period T = {:.4g}", r.period);
    s += fmt::format(", DT = {:.4g}, {}", r.dt, coarse::to_string(r.status));
    if (r.lifted) s += fmt::format(", {} labels changed", changed);
    if (r.repair.changed()) s += fmt::format(", repaired (max {:.3g} d_p)", r.repair.max_adjustment);
    if (!r.message.empty()) s += " [" + r.message + "]";
    return s;
}
}  // namespace

RunSummary run_direct(EnsembleStepper& stepper, const RunSettings& s, Progress& progress, const RunControl& control) {
    const DriverState state = control.resume.value_or(DriverState{stepper.time()});
    const double t_end = state.t_origin + s.duration;
    const long total = std::lround(s.duration / s.observe.interval);
    long done = stepper.samples_taken();
    const long every = control.checkpoint_interval;
    // Chunks of about 10 time units keep the burst buffer small; sampling is unaffected.
    const long chunk = std::max(1L, std::lround(10.0 / s.observe.interval));
    coarse::BurstSamples scratch;
    while (done < total) {
        long n = std::min(chunk, total - done);
        if (every > 0) n = std::min(n, every - done % every);
        scratch = {};
        stepper.run(static_cast<double>(n) * s.observe.interval, scratch);
        done += n;
        if (every > 0 && done % every == 0 && done < total) {
            const auto path = stepper.checkpoint(done, state);
            log::info("checkpoint {} (t = {:.6g})", path.string(), stepper.time());
        }
    }
    stepper.finish();
    progress.update(stepper.time(), stepper.particle_steps(), "done", true);
    RunSummary sum;
    sum.simulated_time = s.duration;
    sum.dem_time = stepper.micro_time();
    sum.wall_seconds = progress.elapsed_seconds();
    sum.particle_steps = stepper.particle_steps();
    sum.restrict_seconds = stepper.overhead().restrict_seconds;
    sum.end_status = std::abs(stepper.time() - t_end) < 1e-6 * std::max(1.0, t_end) ? "completed" : "incomplete";
    return sum;
}

double planned_dem_time(double t_now, double t_end, double burst, double dt) {
    const double tol = kTimeTolerance * std::max(1.0, t_end);
    double dem = 0.0;
    for (double t = t_now; t_end - t >= burst - tol;) {
        t += burst;
        dem += burst;
        t += std::min(dt, coarse::end_of_run_jump_limit(t, t_end, dt, burst));
    }
    return dem;
}

RunSummary run_cpi(EnsembleStepper& stepper, const RunSettings& s, coarse::EnsembleObservable& fallback,
                   RunRecorder* recorder, Progress& progress, const RunControl& control) {
    const DriverState resumed = control.resume.value_or(DriverState{stepper.time()});
    const double t_start = resumed.t_origin;
    const double t_end = t_start + s.duration;
    const bool compact = s.cpi.observable == CpiSettings::Observable::compact;
    // ICDF targets are made non-decreasing and clipped into the heights the particles occupy
    // before lifting (physics.md §9 step 1); each repair is recorded with its step.
    coarse::RepairHook icdf_repair = [&stepper](Eigen::VectorXd& x) {
        const auto [lo, hi] = stepper.height_range();
        return coarse::repair_monotone(x, lo, hi);
    };
    auto integrator = make_integrator(s, compact ? coarse::RepairHook{} : icdf_repair);
    integrator->set_end_time(t_end);
    if (s.cpi.projection == CpiSettings::Projection::periods && stepper.realizations() > 1)
        log::warn("cpi.projection = periods measures the wave period from the ensemble-mean centre of "
                  "mass; with {} realizations the wave phases average out and the period may not be "
                  "measurable. DT = k T is the single-realization method of the paper (Fig. 2b); for "
                  "an ensemble use cpi.projection = fixed", stepper.realizations());
    bool fell_back = false;
    // From here on the full ICDF is the coarse variable (the compact fit failed, now or before
    // the checkpoint this run resumed from).
    auto fall_back_to_icdf = [&] {
        stepper.set_observable(fallback);
        integrator = make_integrator(s, icdf_repair);
        integrator->set_end_time(t_end);
        fell_back = true;
    };
    if (resumed.fell_back) fall_back_to_icdf();
    RunSummary sum;
    sum.end_status = "completed";
    sum.coarse_steps = resumed.coarse_steps;
    long without_progress = resumed.without_progress;
    long last_checkpoint = sum.coarse_steps;
    if (s.cpi.warmup > 0 && !control.resume) {
        // The initial bed (packed, at rest) is far from the slow manifold: run it directly
        // until the fast transients (fluidization) are gone before the first projection.
        coarse::BurstSamples warmup;
        stepper.run(std::min(s.cpi.warmup, s.duration), warmup);
        log::info("warm-up: {:.4g} time units of direct simulation before the first coarse step", s.cpi.warmup);
    }
    while (stepper.time() < t_end - kTimeTolerance * std::max(1.0, t_end)) {
        // Between coarse steps: nothing of the last burst is needed any more.
        const long every = control.checkpoint_interval;
        if (every > 0 && sum.coarse_steps != last_checkpoint && sum.coarse_steps % every == 0) {
            const auto path = stepper.checkpoint(sum.coarse_steps, {t_start, sum.coarse_steps, without_progress, fell_back});
            log::info("checkpoint {} (t = {:.6g}, after coarse step {})", path.string(), stepper.time(), sum.coarse_steps);
            last_checkpoint = sum.coarse_steps;
        }
        // The integrators shorten their jumps to end at t_end; only a run shorter than warm-up
        // plus one burst (or one whose period bursts were extended) can be left with less.
        const double burst = s.cpi.healing + s.cpi.window;
        if (t_end - stepper.time() < burst - kTimeTolerance * std::max(1.0, t_end)) {
            log::info("stopping at t = {:.6g}: the {:.4g} time units left are less than one "
                      "burst ({:.4g})", stepper.time(), t_end - stepper.time(), burst);
            break;
        }
        const coarse::ProjectiveStepRecord rec = integrator->step(stepper);
        ++sum.coarse_steps;
        const LiftRecord lift = rec.lifted ? stepper.last_lift() : LiftRecord{};
        if (recorder) recorder->coarse_step(rec, lift);
        log::info("{}", describe_step(sum.coarse_steps, rec, lift));
        if (stepper.micro_time() > 0.0) {
            const double steps_per_time = stepper.particle_steps() / stepper.micro_time();
            const double dt_next = rec.dt > 0.0 ? rec.dt : rec.dt_requested;
            progress.set_expected_particle_steps(
                stepper.particle_steps() +
                steps_per_time * planned_dem_time(stepper.time(), t_end, burst, dt_next));
        }
        progress.update(stepper.time(), stepper.particle_steps(), "", true);
        if (rec.advanced()) {
            without_progress = 0;
            continue;
        }
        if (compact && !fell_back && rec.status == coarse::StepStatus::invalid_burst) {
            // The compact fit failed (y = 0 at full demixing, or no convergence): continue with
            // the full ICDF, which is always defined.
            // The sample that failed, not the burst's last one (which may have succeeded).
            const std::string failed = stepper.observable().failure_message();
            const std::string why = failed.empty() ? stepper.observable().status_message() : failed;
            log::warn("the compact (A,B,C,D) observable failed at t = {:.6g}: {} ({}); continuing "
                      "with the full ICDF as the coarse variable",
                      stepper.time(), why.empty() ? "the fit is not usable" : why, rec.message);
            fall_back_to_icdf();
            continue;
        }
        if (rec.status == coarse::StepStatus::stopped_unstable ||
            ++without_progress >= kMaxStepsWithoutProgress) {
            sum.end_status = fmt::format("stopped at t = {:.6g}: {} ({})", stepper.time(),
                                         coarse::to_string(rec.status), rec.message);
            log::warn("cpi run {}", sum.end_status);
            break;
        }
    }
    stepper.finish();
    sum.simulated_time = stepper.time() - t_start;
    sum.dem_time = stepper.micro_time();
    sum.wall_seconds = progress.elapsed_seconds();
    sum.particle_steps = stepper.particle_steps();
    sum.restrict_seconds = stepper.overhead().restrict_seconds;
    sum.lift_seconds = stepper.overhead().lift_seconds;
    if (fell_back && sum.end_status == "completed") sum.end_status = "completed (compact observable fell back to icdf)";
    return sum;
}

}  // namespace efdem::mpi_driver
