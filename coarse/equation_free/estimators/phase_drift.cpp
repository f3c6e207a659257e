#include "coarse/equation_free/estimators/phase_drift.hpp"

#include <cmath>
#include <span>
#include <vector>

#include <fmt/format.h>

#include "coarse/equation_free/ensemble_statistics.hpp"
#include "coarse/equation_free/estimators/period_estimator.hpp"
#include "coarse/equation_free/estimators/slope_estimators.hpp"

namespace efdem::coarse {

namespace {
/// The members' scalar signal from sample `first` on, one column per member (samples x R);
/// empty unless every sample has the same R >= 2 values.
Eigen::MatrixXd member_series(const std::vector<Eigen::VectorXd>& signal, std::size_t first) {
    const Eigen::Index r = signal[first].size();
    if (r < 2) return {};
    Eigen::MatrixXd y(static_cast<Eigen::Index>(signal.size() - first), r);
    for (std::size_t k = first; k < signal.size(); ++k) {
        if (signal[k].size() != r) return {};
        y.row(static_cast<Eigen::Index>(k - first)) = signal[k].transpose();
    }
    return y;
}

std::span<const double> column(const Eigen::MatrixXd& y, Eigen::Index m) {
    return {y.col(m).data(), static_cast<std::size_t>(y.rows())};
}
}  // namespace

PhaseDrift phase_drift(const BurstSamples& b, double t_start, double allowed_rate) {
    PhaseDrift d;
    const std::size_t first = first_sample_at_or_after(b.t, t_start);
    const std::vector<Eigen::VectorXd>& signal =
        b.member_expansion.empty() ? b.member_phase : b.member_expansion;
    const char* what =
        b.member_expansion.empty() ? "phase signal" : "bed height (mean particle height)";
    if (signal.size() != b.t.size() || b.t.size() < first + 3) return d;
    const Eigen::MatrixXd y = member_series(signal, first);
    if (y.size() == 0) return d;
    const std::span<const double> t(b.t.data() + first, b.t.size() - first);
    Eigen::MatrixXd slopes(y.cols(), 1);  // one row per member, as slope_standard_error() takes
    for (Eigen::Index m = 0; m < y.cols(); ++m) slopes(m, 0) = fit_line(t, column(y, m)).slope;
    d.measured = true;
    d.slope =
        ensemble_mean(slopes)[0];  // = the slope of the members' mean (least squares is linear)
    d.standard_error = slope_standard_error(slopes)[0];
    d.drifting = std::abs(d.slope) > 2.0 * d.standard_error && std::abs(d.slope) > allowed_rate;
    d.message = fmt::format("{} drifts {:.3g} +- {:.2g} per time unit over t = {:.4g}..{:.4g}",
                            what, d.slope, d.standard_error, t.front(), t.back());
    return d;
}

WaveCoherence wave_coherence(const BurstSamples& b, double t_start) {
    WaveCoherence w;
    const std::size_t first = first_sample_at_or_after(b.t, t_start);
    if (b.member_phase.size() != b.t.size() || b.t.size() < first + 8) return w;
    const Eigen::MatrixXd y = member_series(b.member_phase, first);
    if (y.size() == 0) return w;
    const Eigen::Index r = y.cols();
    const std::span<const double> t(b.t.data() + first, b.t.size() - first);
    auto detrended_square = [&](std::span<const double> v) {
        const LineFit line = fit_line(t, v);
        double sum = 0.0;
        for (std::size_t k = 0; k < t.size(); ++k)
            sum += (v[k] - line.at(t[k])) * (v[k] - line.at(t[k]));
        return sum / static_cast<double>(t.size());
    };
    double members = 0.0;
    for (Eigen::Index m = 0; m < r; ++m)
        members += detrended_square(column(y, m)) / static_cast<double>(r);
    if (!(members > 0.0)) return w;
    const Eigen::VectorXd mean = y.rowwise().mean();
    const std::span<const double> mean_span(mean.data(), static_cast<std::size_t>(mean.size()));
    w.measured = true;
    w.ratio = std::sqrt(detrended_square(mean_span) / (members / static_cast<double>(r)));
    w.threshold = 0.5 * (1.0 + std::sqrt(static_cast<double>(r)));
    PeriodSettings one;
    one.min_periods = 1;
    const PeriodEstimate p = estimate_period(t, mean_span, one);
    // A period is evidence of a wave only when two of it fit in the samples (see
    // WaveCoherence::period); a longer one was seen once.
    if (p.n_periods >= 1 && 2.0 * p.period <= (t.back() - t.front()) * (1.0 + 1e-9))
        w.period = p.period;
    const bool coherent = w.ratio > w.threshold;
    w.in_phase = coherent && std::isfinite(w.period);
    const std::string numbers = fmt::format(
        "the ensemble-mean phase signal fluctuates {:.2f} x as much as independent phases would "
        "give (in "
        "phase: {:.2f}; threshold {:.2f})",
        w.ratio, std::sqrt(static_cast<double>(r)), w.threshold);
    if (coherent && !w.in_phase)
        w.message = fmt::format(
            "the realizations move together but show no wave ({}; no period of the mean that fits "
            "twice in t = {:.4g}..{:.4g}): a shared relaxation or a single swing, not a wave",
            numbers, t.front(), t.back());
    else
        w.message = fmt::format(
            "the realizations' waves are {}in phase: {}{}", w.in_phase ? "" : "not ", numbers,
            std::isfinite(w.period) ? fmt::format(", period {:.3g}", w.period) : std::string{});
    return w;
}

}  // namespace efdem::coarse
