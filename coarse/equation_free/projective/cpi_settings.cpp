#include "coarse/equation_free/projective/cpi_settings.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "core/whole_multiple.hpp"

namespace efdem::coarse {

CpiSettings CpiSettings::from_params(const Params& cpi, double sample_interval, bool for_cpi_run) {
    const char* interval = "observe.interval";
    // Times on the sampling grid: checked only for a run that uses them (a direct run reads the
    // cpi block of its scene without running it).
    auto on_grid = [&](const char* key, double value) -> long {
        if (!for_cpi_run) return std::lround(value / sample_interval);
        return whole_multiple(cpi, key, value, sample_interval, interval);
    };
    CpiSettings s;
    const std::string projection =
        cpi.get_or_choice("projection", "fixed", {"fixed", "periods", "adaptive"});
    s.projection = projection == "periods"    ? Projection::periods
                   : projection == "adaptive" ? Projection::adaptive
                                              : Projection::fixed;
    const bool adaptive = s.projection == Projection::adaptive;
    s.steps = cpi.get_or_choice("integrator", "euler", {"euler", "adams_bashforth2"}) ==
                      "adams_bashforth2"
                  ? 2
                  : 1;
    if (s.steps == 2 && s.projection == Projection::periods)
        cpi.fail("integrator",
                 "needs slopes at known times from every burst; cpi.projection = periods takes "
                 "period means over bursts of varying length",
                 "euler with cpi.projection = periods; adams_bashforth2 with fixed or adaptive");
    s.warmup = cpi.get_or<double>("warmup", 0.0, Bounds::closed(0.0, 1e7));
    on_grid("warmup", s.warmup);
    const double healing = cpi.get_or<double>("healing", 10.0, Bounds::closed(0.0, 1e7));
    on_grid("healing", healing);
    const double window = cpi.get_or<double>("window", 10.0, Bounds::open_closed(0.0, 1e7));
    const long window_samples = on_grid("window", window);
    if (for_cpi_run && window_samples < 3)
        cpi.fail("window",
                 fmt::format("holds {} samples; a slope needs at least 3", window_samples),
                 fmt::format(">= 3 x {} = {:g}", interval, 3 * sample_interval));
    s.fixed.dt = cpi.get_or<double>("dt", 80.0, Bounds::closed(0.0, 1e7));
    if (adaptive) {
        for (const char* key : {"periods", "max_extension"})
            if (cpi.contains(key))
                cpi.fail(key,
                         "is not read with cpi.projection = adaptive (it belongs to cpi.projection "
                         "= periods)",
                         "remove it, or choose cpi.projection = periods");
    } else {
        s.periods.periods_per_step = cpi.get_or<int>("periods", 2, Bounds::closed(0, 1000));
        s.periods.max_extension =
            cpi.get_or<double>("max_extension", 30.0, Bounds::closed(0.0, 1e7));
        on_grid("max_extension", s.periods.max_extension);
        for (const char* key : {"tolerance", "accuracy", "dt_min", "dt_max", "safety", "growth",
                                "window_auto", "window_max", "noisy_curvature", "lift_error"})
            if (cpi.contains(key))
                cpi.fail(
                    key,
                    fmt::format("is read only with cpi.projection = adaptive (this run uses {})",
                                projection),
                    "remove it, or set cpi.projection = adaptive");
    }
    const std::string policy = cpi.get_or_choice("stability", "warn", {"warn", "halve", "stop"});
    const StabilityPolicy stability = policy == "halve"  ? StabilityPolicy::halve_step
                                      : policy == "stop" ? StabilityPolicy::stop
                                                         : StabilityPolicy::warn;
    const BurstSettings burst_settings{
        .healing = healing, .window = window, .stability = stability};
    s.fixed.burst = s.periods.burst = burst_settings;
    MultistepSettings& m = s.multistep;
    m.burst = burst_settings;
    m.steps = s.steps;
    m.adaptive = adaptive;
    m.dt = s.fixed.dt;
    m.dt_quantum = sample_interval;
    m.slope = cpi.get_or_choice("slope", "burst", {"burst", "pooled"}) == "pooled"
                  ? SlopeSource::pooled
                  : SlopeSource::burst;
    m.pool = static_cast<std::size_t>(cpi.get_or<int>("pool", 4, Bounds::closed(1, 64)));
    if (m.slope == SlopeSource::pooled && s.steps == 2)
        cpi.fail("slope",
                 "pooled pools the bursts' slopes into one forward-Euler slope; it does not "
                 "combine with cpi.integrator = adams_bashforth2",
                 "burst with adams_bashforth2; pooled with cpi.integrator = euler");
    m.slope_fit = cpi.get_or_choice("slope_fit", "least_squares", {"least_squares", "increment"}) ==
                          "increment"
                      ? SlopeFit::increment
                      : SlopeFit::least_squares;
    if (m.slope_fit == SlopeFit::increment && s.projection == Projection::periods)
        cpi.fail("slope_fit",
                 "increment is read with cpi.projection = fixed or adaptive; periods takes "
                 "period means, which a wave does not bias",
                 "least_squares with cpi.projection = periods");
    m.pooled_curvature = cpi.get_or_choice("curvature", "none", {"none", "pooled"}) == "pooled";
    if (m.pooled_curvature) {
        if (s.projection == Projection::periods)
            cpi.fail("curvature",
                     "pooled is read with cpi.projection = fixed or adaptive; periods projects "
                     "period means",
                     "none with cpi.projection = periods");
        if (s.steps == 2)
            cpi.fail("curvature",
                     "pooled adds a curvature to forward Euler; cpi.integrator = adams_bashforth2 "
                     "takes its own from the last two slopes",
                     "none with adams_bashforth2; pooled with cpi.integrator = euler");
        if (m.slope == SlopeSource::pooled)
            cpi.fail("curvature",
                     "pooled adds a curvature to the last burst's slope; cpi.slope = pooled "
                     "averages the slopes of the bursts the curvature is fitted to",
                     "none with cpi.slope = pooled; pooled with cpi.slope = burst");
        if (m.pool < MultistepSettings::curvature_min_bursts)
            cpi.fail("pool",
                     fmt::format("is {}: cpi.curvature = pooled fits a curvature to the slopes of "
                                 "the last cpi.pool bursts",
                                 m.pool),
                     fmt::format("at least {} (two slopes are Adams-Bashforth 2's line)",
                                 MultistepSettings::curvature_min_bursts));
    }
    m.healing_auto = cpi.get_or<bool>("healing_auto", false);
    if (m.healing_auto && s.projection == Projection::periods)
        cpi.fail("healing_auto",
                 "is read with cpi.projection = fixed or adaptive; periods sizes its bursts by the "
                 "period",
                 "false with cpi.projection = periods");
    // The shortest healing: a tenth of the burst, on the sampling grid, at least one sample.
    m.healing_min = std::min(
        healing,
        std::max(sample_interval,
                 std::floor(0.1 * (healing + window) / sample_interval + 1e-9) * sample_interval));
    if (m.slope == SlopeSource::pooled && s.projection == Projection::periods)
        cpi.fail("slope",
                 "pooled is read with cpi.projection = fixed or adaptive; periods takes period "
                 "means over bursts of varying length",
                 "burst with cpi.projection = periods");
    if (adaptive) {
        const double burst = healing + window;
        StepSizeSettings& c = m.control;
        // Either the error of one jump (cpi.tolerance, d_p) or of the whole trajectory as a
        // multiple of the ensemble's standard error (cpi.accuracy, trajectory_budget.hpp).
        // Both given: the one on the command line replaces the scene's other (as an override
        // replaces its own key); both in the scene, or both on the command line, is an error.
        bool use_accuracy = cpi.contains("accuracy");
        if (use_accuracy && cpi.contains("tolerance")) {
            const auto on_command_line = [&](const char* key) {
                return cpi.location(key).file == "<command line>";
            };
            if (on_command_line("accuracy") == on_command_line("tolerance"))
                cpi.fail("accuracy",
                         "is given together with cpi.tolerance; the one sets every jump's "
                         "tolerance from the trajectory's budget, the other fixes it",
                         "one of them: cpi.accuracy (the whole trajectory, in the ensemble's "
                         "standard errors) or cpi.tolerance (each jump, in d_p); given on the "
                         "command line, either replaces the scene's other");
            use_accuracy = on_command_line("accuracy");
            // The replaced key still counts as read (and range-checked).
            (void)cpi.get<double>(use_accuracy ? "tolerance" : "accuracy",
                                  Bounds::open_closed(0.0, 1e6));
        }
        if (use_accuracy) m.accuracy = cpi.get<double>("accuracy", Bounds::open_closed(0.0, 1e3));
        c.tolerance = !std::isnan(m.accuracy) ? 1.0  // replaced before every jump
                      : for_cpi_run
                          ? cpi.get<double>("tolerance", Bounds::open_closed(0.0, 1e6))
                          : cpi.get_or<double>("tolerance", 1.0, Bounds::open_closed(0.0, 1e6));
        c.dt_min = cpi.get_or<double>("dt_min", 0.5 * burst, Bounds::open_closed(0.0, 1e7));
        on_grid("dt_min", c.dt_min);
        c.dt_max = cpi.get_or<double>("dt_max", 8.0 * burst, Bounds::open_closed(0.0, 1e7));
        on_grid("dt_max", c.dt_max);
        if (c.dt_min > c.dt_max)
            cpi.fail("dt_min", fmt::format("is larger than cpi.dt_max = {:g}", c.dt_max),
                     "cpi.dt_min <= cpi.dt_max");
        c.safety = cpi.get_or<double>("safety", 0.8, Bounds::open_closed(0.0, 1.0));
        c.growth = cpi.get_or<double>("growth", 2.0, Bounds::open_closed(1.0, 100.0));
        // The window from evidence (window_noise.hpp): at least 4 samples (2 per half, what
        // the measurement needs), at most cpi.window_max.
        const std::string noisy =
            cpi.get_or_choice("noisy_curvature", "ignored", {"ignored", "counted", "pooled"});
        m.noisy_curvature = noisy == "counted"  ? MultistepSettings::NoisyCurvature::counted
                            : noisy == "pooled" ? MultistepSettings::NoisyCurvature::pooled
                                                : MultistepSettings::NoisyCurvature::ignored;
        if (m.noisy_curvature == MultistepSettings::NoisyCurvature::pooled) {
            if (m.steps != 1)
                cpi.fail("noisy_curvature",
                         "pooled fits the curvature forward Euler's truncation comes from; "
                         "cpi.integrator = adams_bashforth2's comes from the next derivative",
                         "ignored or counted with cpi.integrator = adams_bashforth2");
            if (m.pooled_curvature)
                cpi.fail("noisy_curvature",
                         "pooled charges the curvature fitted to the pooled bursts, which "
                         "cpi.curvature = pooled already adds to every jump",
                         "ignored or counted with cpi.curvature = pooled");
            if (m.slope == SlopeSource::pooled)
                cpi.fail("noisy_curvature",
                         "pooled fits a curvature to the slopes cpi.slope = pooled averages",
                         "ignored or counted with cpi.slope = pooled");
            if (m.pool < 2)
                cpi.fail(
                    "pool",
                    fmt::format("is {}: cpi.noisy_curvature = pooled fits a curvature to the "
                                "slopes of the last cpi.pool bursts and the one after the jump",
                                m.pool),
                    "at least 2 (one burst and the one after the jump are the jump's own "
                    "divided difference)");
        }
        // The lift's own error in X is part of the jump's (docs/error_control.md §4); ignored:
        // as before it was (studies that compare with runs made then).
        m.count_lift_error =
            cpi.get_or_choice("lift_error", "counted", {"counted", "ignored"}) == "counted";
        m.window_auto = cpi.get_or<bool>("window_auto", false);
        m.window_min = 4.0 * sample_interval;
        m.window_max =
            cpi.get_or<double>("window_max", 4.0 * burst, Bounds::closed(m.window_min, 1e7));
        on_grid("window_max", m.window_max);
        if (m.window_auto && m.slope_fit == SlopeFit::increment)
            cpi.fail("window_auto",
                     "chooses the window from how a least-squares slope's noise falls with it; "
                     "cpi.slope_fit = increment is a different estimator",
                     "false with cpi.slope_fit = increment (set cpi.window), or cpi.slope_fit = "
                     "least_squares");
        if (m.window_auto && window > m.window_max)
            cpi.fail("window", fmt::format("is longer than cpi.window_max = {:g}", m.window_max),
                     "cpi.window <= cpi.window_max with cpi.window_auto");
        if (cpi.contains("dt")) {
            if (s.fixed.dt < c.dt_min || s.fixed.dt > c.dt_max)
                cpi.fail(
                    "dt",
                    fmt::format(
                        "caps the first jump with cpi.projection = adaptive and must lie in "
                        "cpi.dt_min..cpi.dt_max = {:g}..{:g}",
                        c.dt_min, c.dt_max),
                    fmt::format(
                        "{:g} <= cpi.dt <= {:g}, or leave it out (first jump from the tolerance)",
                        c.dt_min, c.dt_max));
            m.first_dt = s.fixed.dt;
        }
        // cpi.accuracy: no drift threshold until the ensemble's noise is measured (the
        // integrator then holds jumps by the budget per burst); the first burst makes none.
        m.drift_rate = std::isnan(m.accuracy) ? steady_drift_rate(c.tolerance, burst)
                                              : std::numeric_limits<double>::infinity();
        const Params debug = cpi.scope("debug");
        const std::string force =
            debug.get_or_choice("force", "none", {"none", "reject", "shrink"});
        m.force.kind = force == "reject"   ? ForcedDecision::Kind::reject
                       : force == "shrink" ? ForcedDecision::Kind::shrink
                                           : ForcedDecision::Kind::none;
        m.force.attempt = debug.get_or<long>("force_attempt", 1, Bounds::closed(1, 1000000));
    }
    // cpi.accuracy has no tolerance to judge the warm-up's drift by before the run has measured
    // its noise: the warm-up then runs cpi.warmup (or, asked for, until its drift is in its noise).
    const bool by_tolerance = adaptive && std::isnan(m.accuracy);
    s.warmup_until_steady = cpi.get_or_choice("warmup_until", by_tolerance ? "steady" : "time",
                                              {"time", "steady"}) == "steady";
    s.warmup_max =
        cpi.get_or<double>("warmup_max", 10.0 * (healing + window), Bounds::closed(0.0, 1e7));
    on_grid("warmup_max", s.warmup_max);
    s.warmup_drift_rate = by_tolerance ? m.drift_rate : 0.0;
    const std::string finish =
        cpi.get_or_choice("finish", "duration", {"duration", "steady", "at_rest"});
    s.finish_at_end_state = finish != "duration";
    s.finish_on_drift = finish == "steady";
    if (cpi.contains("jump_until")) {
        if (s.projection == Projection::periods)
            cpi.fail("jump_until", "is not read by cpi.projection = periods",
                     "cpi.projection = fixed or adaptive");
        s.jump_until = cpi.get<double>("jump_until", Bounds::closed(0.0, 1e9));
        on_grid("jump_until", s.jump_until);
    }
    // Extensions must land on samples: 5 time units rounded to whole sampling intervals.
    s.periods.extension_step = std::max(1.0, std::round(5.0 / sample_interval)) * sample_interval;
    return s;
}

double steady_drift_rate(double tolerance, double burst) {
    return tolerance / burst;
}

double CpiSettings::burst() const {
    return projection == Projection::periods ? periods.burst.healing + periods.burst.window
                                             : fixed.burst.healing + fixed.burst.window;
}

double CpiSettings::window() const {
    return projection == Projection::periods ? periods.burst.window : fixed.burst.window;
}

std::unique_ptr<ProjectiveIntegrator> CpiSettings::make_integrator(RepairHook repair) const {
    if (projection == Projection::adaptive ||
        (projection == Projection::fixed &&
         (steps == 2 || multistep.slope == SlopeSource::pooled ||
          multistep.slope_fit == SlopeFit::increment || multistep.pooled_curvature ||
          multistep.healing_auto || multistep.lift_apart || std::isfinite(jump_until))))
        return std::make_unique<MultistepProjectiveIntegrator>(multistep, std::move(repair));
    if (projection == Projection::fixed)
        return std::make_unique<ProjectiveForwardEuler>(fixed, std::move(repair));
    return std::make_unique<PeriodProjectiveEuler>(periods, std::move(repair));
}

}  // namespace efdem::coarse
