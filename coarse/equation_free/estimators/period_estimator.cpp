#include "coarse/equation_free/estimators/period_estimator.hpp"

#include <cmath>
#include <numbers>

#include <Eigen/QR>

#include <fmt/format.h>

#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

/// Upward zero crossings of signal - trend with a Schmitt trigger: armed at or below -band,
/// fired at or above +band, the crossing being the last upward sign change in between; band =
/// `fraction` times the RMS of the detrended signal. At the window edges a rising passage that
/// the band cannot frame still counts: the start arms when the signal starts below zero, and a
/// pending sign change counts when the signal ends above zero. Noise smaller than the band then
/// moves an edge crossing no more than an interior one. Empty if the detrended signal is zero.
std::vector<double> upward_crossings(std::span<const double> t, std::span<const double> signal,
                                     const LineFit& trend, double fraction) {
    std::vector<double> r(t.size());
    double sum_sq = 0.0;
    for (std::size_t k = 0; k < t.size(); ++k) {
        r[k] = signal[k] - trend.at(t[k]);
        sum_sq += r[k] * r[k];
    }
    std::vector<double> crossings;
    if (sum_sq == 0.0) return crossings;
    const double band = fraction * std::sqrt(sum_sq / static_cast<double>(t.size()));
    bool armed = r.front() < 0.0;
    bool have_candidate = false;
    double candidate = 0.0;
    for (std::size_t k = 0; k < t.size(); ++k) {
        if (k > 0 && r[k - 1] < 0.0 && r[k] >= 0.0) {
            candidate = t[k - 1] + (t[k] - t[k - 1]) * (-r[k - 1]) / (r[k] - r[k - 1]);
            have_candidate = true;
        }
        if (r[k] <= -band) {
            armed = true;
            have_candidate = false;
        } else if (armed && have_candidate && r[k] >= band) {
            crossings.push_back(candidate);
            armed = false;
            have_candidate = false;
        }
    }
    if (armed && have_candidate && r.back() > 0.0) crossings.push_back(candidate);
    return crossings;
}

/// The line of a joint least-squares fit of a line and the first `harmonics` harmonics of the
/// period, each with a linearly varying amplitude (tau = t - t_mid, w = 2 pi/period):
///   s ~ c0 + c1 tau + sum_k [(a_k + a'_k tau) cos(k w tau) + (b_k + b'_k tau) sin(k w tau)].
/// Fitting the oscillation together with the line keeps it from leaking into the slope; the
/// tau-modulated terms absorb a small error in w (sin((w + dw) tau) = sin(w tau) +
/// dw tau cos(w tau) + ...), so the slope's error is second order in the period's error and
/// the refinement contracts towards the true period.
LineFit harmonic_trend(std::span<const double> t, std::span<const double> signal, double period,
                       int harmonics) {
    const auto n = static_cast<Eigen::Index>(t.size());
    const double t_mid = 0.5 * (t.front() + t.back());
    const double w = 2.0 * std::numbers::pi / period;
    Eigen::MatrixXd basis(n, 2 + 4 * harmonics);
    for (Eigen::Index k = 0; k < n; ++k) {
        const double tau = t[static_cast<std::size_t>(k)] - t_mid;
        basis(k, 0) = 1.0;
        basis(k, 1) = tau;
        for (int j = 0; j < harmonics; ++j) {
            const double c = std::cos((j + 1) * w * tau), s = std::sin((j + 1) * w * tau);
            basis.row(k).segment(2 + 4 * j, 4) << c, s, tau * c, tau * s;
        }
    }
    const Eigen::Map<const Eigen::VectorXd> y(signal.data(), n);
    const Eigen::VectorXd coefficients = basis.colPivHouseholderQr().solve(y);
    return {coefficients[1], t_mid, coefficients[0]};
}

}  // namespace

PeriodEstimate estimate_period(std::span<const double> t, std::span<const double> signal,
                               const PeriodSettings& settings) {
    EFDEM_EXPECTS(t.size() >= 2 && signal.size() == t.size());
    EFDEM_EXPECTS(settings.min_periods >= 1 && settings.refinements >= 0);
    EFDEM_EXPECTS(settings.harmonics >= 1);
    EFDEM_EXPECTS(settings.hysteresis > 0.0 && settings.hysteresis < 1.0);

    PeriodEstimate est;
    est.crossings = upward_crossings(t, signal, fit_line(t, signal), settings.hysteresis);
    auto spacing = [](const std::vector<double>& c) {
        return (c.back() - c.front()) / static_cast<double>(c.size() - 1);
    };
    // Each pass needs two periods for a meaningful harmonic fit. If a pass finds fewer
    // crossings, the extra one came from the biased trend: keep the pass's answer (too few
    // periods) rather than the biased estimate.
    const auto n_coefficients = static_cast<std::size_t>(2 + 4 * settings.harmonics);
    for (int pass = 0;
         pass < settings.refinements && est.crossings.size() >= 3 && t.size() > 2 * n_coefficients;
         ++pass) {
        const double period = spacing(est.crossings);
        est.crossings = upward_crossings(
            t, signal, harmonic_trend(t, signal, period, settings.harmonics), settings.hysteresis);
        if (est.crossings.size() >= 2 &&
            std::abs(spacing(est.crossings) - period) <= 1e-14 * period)
            break;
    }

    est.n_periods = est.crossings.empty() ? 0 : static_cast<int>(est.crossings.size()) - 1;
    if (est.n_periods >= 1) est.period = spacing(est.crossings);
    if (est.n_periods >= settings.min_periods) {
        est.status = PeriodStatus::ok;
    } else {
        est.message = fmt::format(
            "found {} upward zero crossing(s) ({} full period(s)) of the detrended phase signal "
            "in [{:.6g}, {:.6g}]; at least {} full periods are needed: lengthen the burst",
            est.crossings.size(), est.n_periods, t.front(), t.back(), settings.min_periods);
    }
    return est;
}

}  // namespace efdem::coarse
