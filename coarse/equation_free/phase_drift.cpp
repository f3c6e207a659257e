#include "coarse/equation_free/phase_drift.hpp"

#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "coarse/equation_free/period_estimator.hpp"
#include "coarse/equation_free/slope_estimators.hpp"

namespace efdem::coarse {

PhaseDrift phase_drift(const BurstSamples& b, double t_start, double allowed_rate) {
    PhaseDrift d;
    const std::size_t first = first_sample_at_or_after(b.t, t_start);
    const std::vector<Eigen::VectorXd>& signal = b.member_expansion.empty() ? b.member_phase : b.member_expansion;
    const char* what = b.member_expansion.empty() ? "phase signal" : "bed height (mean particle height)";
    if (signal.size() != b.t.size() || b.t.size() < first + 3) return d;
    const Eigen::Index r = signal[first].size();
    if (r < 2) return d;
    const std::span<const double> t(b.t.data() + first, b.t.size() - first);
    Eigen::VectorXd slopes(r);
    std::vector<double> y(t.size());
    for (Eigen::Index m = 0; m < r; ++m) {
        for (std::size_t k = 0; k < t.size(); ++k) {
            if (signal[first + k].size() != r) return d;
            y[k] = signal[first + k][m];
        }
        slopes[m] = fit_line(t, y).slope;
    }
    d.measured = true;
    d.slope = slopes.mean();  // = the slope of the members' mean (least squares is linear)
    d.standard_error = std::sqrt((slopes.array() - d.slope).square().sum() / static_cast<double>(r - 1) /
                                 static_cast<double>(r));
    d.drifting = std::abs(d.slope) > 2.0 * d.standard_error && std::abs(d.slope) > allowed_rate;
    d.message = fmt::format("{} drifts {:.3g} +- {:.2g} per time unit over t = {:.4g}..{:.4g}", what, d.slope,
                            d.standard_error, t.front(), t.back());
    return d;
}

WaveCoherence wave_coherence(const BurstSamples& b, double t_start) {
    WaveCoherence w;
    const std::size_t first = first_sample_at_or_after(b.t, t_start);
    if (b.member_phase.size() != b.t.size() || b.t.size() < first + 8) return w;
    const Eigen::Index r = b.member_phase[first].size();
    if (r < 2) return w;
    const std::span<const double> t(b.t.data() + first, b.t.size() - first);
    std::vector<double> y(t.size()), mean(t.size(), 0.0);
    auto detrended_square = [&](const std::vector<double>& v) {
        const LineFit line = fit_line(t, v);
        double sum = 0.0;
        for (std::size_t k = 0; k < t.size(); ++k) sum += (v[k] - line.at(t[k])) * (v[k] - line.at(t[k]));
        return sum / static_cast<double>(t.size());
    };
    double members = 0.0;
    for (Eigen::Index m = 0; m < r; ++m) {
        for (std::size_t k = 0; k < t.size(); ++k) {
            if (b.member_phase[first + k].size() != r) return w;
            y[k] = b.member_phase[first + k][m];
            mean[k] += y[k] / static_cast<double>(r);
        }
        members += detrended_square(y) / static_cast<double>(r);
    }
    if (!(members > 0.0)) return w;
    w.measured = true;
    w.ratio = std::sqrt(detrended_square(mean) / (members / static_cast<double>(r)));
    w.threshold = 0.5 * (1.0 + std::sqrt(static_cast<double>(r)));
    w.in_phase = w.ratio > w.threshold;
    PeriodSettings one;
    one.min_periods = 1;
    const PeriodEstimate p = estimate_period(t, mean, one);
    if (p.n_periods >= 1) w.period = p.period;
    w.message = fmt::format("the realizations' waves are {}in phase: the ensemble-mean phase signal fluctuates {:.2f} x "
                            "as much as independent phases would give (in phase: {:.2f}; threshold {:.2f}){}",
                            w.in_phase ? "" : "not ", w.ratio, std::sqrt(static_cast<double>(r)), w.threshold,
                            std::isfinite(w.period) ? fmt::format(", period {:.3g}", w.period) : std::string{});
    return w;
}

}  // namespace efdem::coarse
