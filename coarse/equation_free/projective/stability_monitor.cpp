#include "coarse/equation_free/projective/stability_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "coarse/equation_free/estimators/mean_significance.hpp"
#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

DecayRateEstimate decay_rate_from_slopes(const Eigen::VectorXd& early, const Eigen::VectorXd& late,
                                         double delay) {
    EFDEM_EXPECTS(early.size() == late.size() && delay > 0.0);
    DecayRateEstimate est;
    est.delay = delay;
    const double norm2 = early.squaredNorm();
    if (norm2 == 0.0) {
        est.message = "the slope over the first half of the window is zero: no decay rate";
        return est;
    }
    est.ratio = early.dot(late) / norm2;
    if (est.ratio <= 0.0) {
        est.message = fmt::format(
            "the slope reverses between the two halves of the window (ratio {:.3g}): an "
            "oscillation or noise dominates, no single decay rate",
            est.ratio);
        return est;
    }
    est.rate = std::log(est.ratio) / delay;
    est.ok = true;
    return est;
}

namespace {
/// The two halves of the window t >= t_start: [t_first, t_mid] (samples before early_end) and
/// [t_mid, t_last]; a sample at t_mid belongs to both. Not ok with fewer than 4 samples.
struct Halves {
    bool ok = false;
    std::size_t first = 0, early_end = 0;
    double t_mid = 0.0;
};

Halves window_halves(std::span<const double> t, double t_start) {
    Halves h;
    h.first = first_sample_at_or_after(t, t_start);
    if (t.size() < h.first + 4) return h;
    h.t_mid = 0.5 * (t[h.first] + t.back());
    const std::size_t late_first = first_sample_at_or_after(t, h.t_mid);
    h.early_end = t[late_first] <= h.t_mid + time_tolerance(h.t_mid) ? late_first + 1 : late_first;
    h.ok = true;
    return h;
}
}  // namespace

DecayRateEstimate estimate_decay_rate(std::span<const double> t, std::span<const Eigen::VectorXd> x,
                                      double t_start) {
    EFDEM_EXPECTS(x.size() == t.size());
    const Halves h = window_halves(t, t_start);
    DecayRateEstimate est;
    if (!h.ok) {
        est.message =
            fmt::format("the window t >= {:.6g} holds {} samples; the decay-rate estimate needs 4",
                        t_start, t.size() - std::min(h.first, t.size()));
        return est;
    }
    const SlopeEstimate early =
        least_squares_slope(t.first(h.early_end), x.first(h.early_end), t_start);
    const SlopeEstimate late = least_squares_slope(t, x, h.t_mid);
    if (!early.ok || !late.ok) {
        est.message = !early.ok ? early.message : late.message;
        return est;
    }
    return decay_rate_from_slopes(early.slope, late.slope, h.t_mid - t[h.first]);
}

DecayResolution decay_resolution(std::span<const double> t,
                                 std::span<const Eigen::MatrixXd> members, double t_start) {
    DecayResolution r;
    const Halves h = window_halves(t, t_start);
    if (!h.ok || members.size() != t.size()) return r;
    const Eigen::MatrixXd early =
        member_least_squares_slopes(t.first(h.early_end), members.first(h.early_end), t_start);
    const Eigen::MatrixXd late = member_least_squares_slopes(t, members, h.t_mid);
    if (early.rows() < 2 || late.rows() != early.rows()) return r;
    // Each member's change of slope between the halves: is the ensemble's change above the
    // members' scatter?
    const MeanSignificance m = mean_significance(late - early);
    r.measured = m.measured;
    r.resolved = m.resolved;
    r.statistic = m.statistic;
    r.threshold = m.threshold;
    return r;
}

DecayRateEstimate estimate_decay_rate_periodic(std::span<const double> t,
                                               std::span<const Eigen::VectorXd> x, double period,
                                               double t_start, double t_end) {
    EFDEM_EXPECTS(period > 0.0 && x.size() == t.size());
    DecayRateEstimate est;
    if (t_end - 3.0 * period < t_start - time_tolerance(t_start)) {
        est.message = fmt::format(
            "the window [{:.6g}, {:.6g}] holds fewer than three periods (T = {:.6g}); the "
            "decay-rate estimate needs three",
            t_start, t_end, period);
        return est;
    }
    const std::size_t first = first_sample_at_or_after(t, t_start);
    const auto tw = t.subspan(first);
    const auto xw = x.subspan(first);
    const SlopeEstimate early = period_mean_slope(tw, xw, period, t_end - period);
    const SlopeEstimate late = period_mean_slope(tw, xw, period, t_end);
    if (!early.ok || !late.ok) {
        est.message = !early.ok ? early.message : late.message;
        return est;
    }
    return decay_rate_from_slopes(early.slope, late.slope, period);
}

StabilityAssessment assess_stability(const DecayRateEstimate& decay, const CpiCycle& cycle) {
    StabilityAssessment a;
    if (!decay.ok) {
        a.message = "stability not assessed: " + decay.message;
        return a;
    }
    a.assessed = true;
    a.rate = decay.rate;
    if (decay.rate >= 0.0) {
        a.message = fmt::format("no decaying transient in the window (lambda = {:.3g})", a.rate);
        return a;
    }
    a.amplification = cpi_amplification(cycle, a.rate);
    a.exact = std::exp(a.rate * (cycle.burst + cycle.dt));
    a.stable = std::abs(a.amplification) <= 1.0;
    a.message = fmt::format(
        "measured transient lambda = {:.4g} per unit time: G(lambda) = {:.4g} for DT = {:.6g} "
        "(burst {:.6g}, {} {:.6g}; exact factor {:.4g}){}",
        a.rate, a.amplification, cycle.dt, cycle.burst,
        cycle.estimator == SlopeEstimator::period_mean ? "period" : "window", cycle.window, a.exact,
        a.stable ? ""
                 : ": |G| > 1, the projective step would amplify this mode (physics.md §10; "
                   "cure: longer healing or smaller DT)");
    return a;
}

}  // namespace efdem::coarse
