#include "coarse/equation_free/phase_drift.hpp"

#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "coarse/equation_free/slope_estimators.hpp"

namespace efdem::coarse {

PhaseDrift phase_drift(const BurstSamples& b, double t_start, double allowed_rate) {
    PhaseDrift d;
    const std::size_t first = first_sample_at_or_after(b.t, t_start);
    if (b.member_phase.size() != b.t.size() || b.t.size() < first + 3) return d;
    const Eigen::Index r = b.member_phase[first].size();
    if (r < 2) return d;
    const std::span<const double> t(b.t.data() + first, b.t.size() - first);
    Eigen::VectorXd slopes(r);
    std::vector<double> y(t.size());
    for (Eigen::Index m = 0; m < r; ++m) {
        for (std::size_t k = 0; k < t.size(); ++k) {
            if (b.member_phase[first + k].size() != r) return d;
            y[k] = b.member_phase[first + k][m];
        }
        slopes[m] = fit_line(t, y).slope;
    }
    d.measured = true;
    d.slope = slopes.mean();  // = the slope of the members' mean (least squares is linear)
    d.standard_error = std::sqrt((slopes.array() - d.slope).square().sum() / static_cast<double>(r - 1) /
                                 static_cast<double>(r));
    d.drifting = std::abs(d.slope) > 2.0 * d.standard_error && std::abs(d.slope) > allowed_rate;
    d.message = fmt::format("phase signal (centre of mass) drifts {:.3g} +- {:.2g} per time unit over t = {:.4g}..{:.4g}",
                            d.slope, d.standard_error, t.front(), t.back());
    return d;
}

}  // namespace efdem::coarse
