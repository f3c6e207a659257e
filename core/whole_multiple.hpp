#pragma once
/// \file
/// whole_multiple: a scene time that must be a whole number of a finer time (a sampling
/// interval of time steps, a burst of sampling intervals), so that samples fall exactly on
/// steps. Used by every room that reads such a key (run settings, the coarse run loop).

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "core/param_table.hpp"

namespace efdem {

/// The number of steps of size `dt` in `duration`, or an InputError on `key` of `scope` if
/// `duration` is not a whole multiple of `dt` (to 1e-9 relative); `dt_name` names dt in the
/// message (e.g. "observe.interval").
inline long whole_multiple(const Params& scope, const char* key, double duration, double dt,
                           const std::string& dt_name) {
    const double n = std::round(duration / dt);
    if (duration > 0 && n < 1)
        scope.fail(key,
                   fmt::format("is shorter than {} = {:g}: it would be taken as no {} at all",
                               dt_name, dt, dt_name),
                   fmt::format("0 or a multiple of {:g}, e.g. {:g}", dt, dt));
    if (std::abs(n * dt - duration) > 1e-9 * std::max(duration, dt))
        scope.fail(key, fmt::format("is not a whole multiple of {} = {:g}", dt_name, dt),
                   fmt::format("a multiple of {:g}, e.g. {:g}", dt, std::max(1.0, n) * dt));
    return static_cast<long>(n);
}

}  // namespace efdem
