#pragma once
// The projective integrator's settings for a fixed-DT test: bursts of `healing` + `window` and
// jumps of `dt`, everything else at its default. The tests that need more set it on the result.
#include "coarse/equation_free/projective/multistep_projective_integrator.hpp"

namespace efdem::test {

inline coarse::MultistepSettings fixed_schedule(double healing, double window, double dt) {
    coarse::MultistepSettings s;
    s.burst.healing = healing;
    s.burst.window = window;
    s.adaptive = false;
    s.dt = dt;
    return s;
}

}  // namespace efdem::test
