#include "coarse/equation_free/projective/step_size_controller.hpp"

#include <cmath>

#include "core/contracts.hpp"

namespace efdem::coarse {

JumpError jump_error(const JumpErrorModel& model, double dt) {
    EFDEM_EXPECTS(dt >= 0.0 && !model.nodes.empty());
    const std::vector<double> w = projection_weights(model.nodes, model.t0, dt);
    JumpError e;
    e.statistical = model.se_scale * rms(statistical_error(model.nodes, w));
    if (std::isfinite(model.curvature))
        e.truncation = model.curvature * omega_integral(model.nodes, model.t0, dt);
    return e;
}

double largest_dt_within(const JumpErrorModel& model, double target, double cap) {
    EFDEM_EXPECTS(target >= 0.0 && cap >= 0.0 && std::isfinite(cap));
    if (jump_error(model, cap).total() <= target) return cap;
    double lo = 0.0, hi = cap;  // error(lo) <= target < error(hi)
    while (hi - lo > 1e-6 * hi) {
        const double mid = 0.5 * (lo + hi);
        (jump_error(model, mid).total() <= target ? lo : hi) = mid;
    }
    return lo;
}

}  // namespace efdem::coarse
