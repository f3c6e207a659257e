#include "coarse/equation_free/coarse_run_settings.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "core/whole_multiple.hpp"

namespace efdem::coarse {

CoarseRunSettings CoarseRunSettings::from_params(const Params& cpi, double sample_interval) {
    const char* interval = "observe.interval";
    CoarseRunSettings s;
    s.projection = cpi.get_or_choice("projection", "fixed", {"fixed", "periods"}) == "periods"
                       ? Projection::periods
                       : Projection::fixed;
    s.warmup = cpi.get_or<double>("warmup", 0.0, Bounds::non_negative());
    whole_multiple(cpi, "warmup", s.warmup, sample_interval, interval);
    const double healing = cpi.get_or<double>("healing", 10.0, Bounds::non_negative());
    whole_multiple(cpi, "healing", healing, sample_interval, interval);
    const double window = cpi.get_or<double>("window", 10.0, Bounds::positive());
    const long window_samples = whole_multiple(cpi, "window", window, sample_interval, interval);
    if (window_samples < 3)
        cpi.fail("window", fmt::format("holds {} samples; a slope needs at least 3", window_samples),
                 fmt::format(">= 3 x {} = {:g}", interval, 3 * sample_interval));
    s.fixed.dt = cpi.get_or<double>("dt", 80.0, Bounds::non_negative());
    s.periods.periods_per_step = cpi.get_or<int>("periods", 2, Bounds::closed(0, 1000));
    s.periods.max_extension = cpi.get_or<double>("max_extension", 30.0, Bounds::non_negative());
    whole_multiple(cpi, "max_extension", s.periods.max_extension, sample_interval, interval);
    const std::string policy = cpi.get_or_choice("stability", "warn", {"warn", "halve", "stop"});
    const StabilityPolicy stability = policy == "halve"  ? StabilityPolicy::halve_step
                                      : policy == "stop" ? StabilityPolicy::stop
                                                         : StabilityPolicy::warn;
    s.fixed.healing = s.periods.healing = healing;
    s.fixed.window = s.periods.window = window;
    s.fixed.stability_policy = s.periods.stability_policy = stability;
    // Extensions must land on samples: 5 time units rounded to whole sampling intervals.
    s.periods.extension_step = std::max(1.0, std::round(5.0 / sample_interval)) * sample_interval;
    return s;
}

double CoarseRunSettings::burst() const {
    return projection == Projection::fixed ? fixed.healing + fixed.window : periods.healing + periods.window;
}

std::unique_ptr<ProjectiveIntegrator> CoarseRunSettings::make_integrator(RepairHook repair) const {
    if (projection == Projection::fixed) return std::make_unique<ProjectiveForwardEuler>(fixed, std::move(repair));
    return std::make_unique<PeriodProjectiveEuler>(periods, std::move(repair));
}

}  // namespace efdem::coarse
