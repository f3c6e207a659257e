#include "coarse/equation_free/estimators/slope_estimators.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "coarse/equation_free/ensemble_statistics.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

// The estimators are written once for scalar and vector series.
double zero_like(double) {
    return 0.0;
}
Eigen::VectorXd zero_like(const Eigen::VectorXd& v) {
    return Eigen::VectorXd::Zero(v.size());
}

[[maybe_unused]] bool strictly_increasing(std::span<const double> t) {
    return std::adjacent_find(t.begin(), t.end(), std::greater_equal<>()) == t.end();
}

/// Least-squares line through the whole series (two-pass sums).
template <class V>
struct Line {
    V slope;
    V mean;
    double t_mean;
};

template <class V>
Line<V> least_squares_line(std::span<const double> t, std::span<const V> x) {
    const auto n = static_cast<double>(t.size());
    double t_mean = 0.0;
    V x_mean = zero_like(x[0]);
    for (std::size_t k = 0; k < t.size(); ++k) {
        t_mean += t[k];
        x_mean += x[k];
    }
    t_mean /= n;
    x_mean /= n;
    double stt = 0.0;
    V stx = zero_like(x[0]);
    for (std::size_t k = 0; k < t.size(); ++k) {
        const double dt = t[k] - t_mean;
        stt += dt * dt;
        stx += dt * (x[k] - x_mean);
    }
    return {stx / stt, x_mean, t_mean};
}

/// Integral over [a, b] of the piecewise-linear interpolant; a, b clamped into [t_0, t_last].
template <class V>
V interval_integral(std::span<const double> t, std::span<const V> x, double a, double b) {
    EFDEM_EXPECTS(t.size() >= 2 && x.size() == t.size());
    EFDEM_EXPECTS(a >= t.front() - time_tolerance(a) && b <= t.back() + time_tolerance(b));
    EFDEM_EXPECTS(a < b);
    a = std::max(a, t.front());
    b = std::min(b, t.back());
    // Segment j holds [t_j, t_{j+1}]; the segment containing s is the last j with t_j <= s.
    auto segment = [&](double s) {
        const auto it = std::upper_bound(t.begin(), t.end(), s);
        const auto j = static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - t.begin() - 1, 0));
        return std::min(j, t.size() - 2);
    };
    auto value_at = [&](std::size_t j, double s) -> V {
        const double w = (s - t[j]) / (t[j + 1] - t[j]);
        return x[j] + w * (x[j + 1] - x[j]);
    };
    const std::size_t ja = segment(a), jb = segment(b);
    if (ja == jb) return (0.5 * (b - a)) * (value_at(ja, a) + value_at(ja, b));
    V sum = (0.5 * (t[ja + 1] - a)) * (value_at(ja, a) + x[ja + 1]);
    for (std::size_t j = ja + 1; j < jb; ++j) sum += (0.5 * (t[j + 1] - t[j])) * (x[j] + x[j + 1]);
    sum += (0.5 * (b - t[jb])) * (x[jb] + value_at(jb, b));
    return sum;
}

/// Applies a vector-series slope estimator to each member's own series (see
/// member_least_squares_slopes()); empty if the members are missing or of mixed shape, or the
/// estimator finds no slope.
template <class Estimator>
Eigen::MatrixXd slopes_per_member(std::span<const double> t,
                                  std::span<const Eigen::MatrixXd> members, Estimator estimate) {
    if (members.empty() || members.size() != t.size()) return {};
    const Eigen::Index n_members = members.front().rows(), dim = members.front().cols();
    for (const Eigen::MatrixXd& m : members)
        if (m.rows() != n_members || m.cols() != dim) return {};
    Eigen::MatrixXd slopes(n_members, dim);
    std::vector<Eigen::VectorXd> series(members.size());
    for (Eigen::Index r = 0; r < n_members; ++r) {
        for (std::size_t k = 0; k < members.size(); ++k) series[k] = members[k].row(r).transpose();
        const SlopeEstimate est = estimate(std::span<const Eigen::VectorXd>(series));
        if (!est.ok) return {};
        slopes.row(r) = est.slope.transpose();
    }
    return slopes;
}

}  // namespace

double time_tolerance(double t) {
    return 1e-9 * std::max(1.0, std::abs(t));
}

std::size_t first_sample_at_or_after(std::span<const double> t, double t_start) {
    const double threshold = t_start - time_tolerance(t_start);
    return static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), threshold) - t.begin());
}

namespace {

/// The window's first sample and count in `est`; false (with est.message) when it holds fewer
/// than two samples. `what` names the estimator in the message.
bool open_window(std::span<const double> t, [[maybe_unused]] std::size_t x_size, double t_start,
                 const char* what, SlopeEstimate& est, std::size_t& first) {
    EFDEM_EXPECTS(x_size == t.size());
    EFDEM_EXPECTS(strictly_increasing(t));
    first = first_sample_at_or_after(t, t_start);
    est.n_samples = static_cast<Eigen::Index>(t.size() - first);
    if (est.n_samples >= 2) return true;
    est.message = fmt::format(
        "{} slope needs at least 2 samples at t >= {:.6g}, the burst has {} "
        "(lengthen the estimation window or sample more often)",
        what, t_start, est.n_samples);
    return false;
}

}  // namespace

SlopeEstimate least_squares_slope(std::span<const double> t, std::span<const Eigen::VectorXd> x,
                                  double t_start) {
    SlopeEstimate est;
    std::size_t first = 0;
    if (!open_window(t, x.size(), t_start, "least-squares", est, first)) return est;
    const auto tw = t.subspan(first);
    const auto xw = x.subspan(first);
    const Line<Eigen::VectorXd> line = least_squares_line(tw, xw);
    est.slope = line.slope;
    est.t_mean = line.t_mean;
    est.t_first = tw.front();
    est.t_last = tw.back();
    est.ok = true;
    return est;
}

SlopeEstimate increment_slope(std::span<const double> t, std::span<const Eigen::VectorXd> x,
                              double t_start) {
    SlopeEstimate est;
    std::size_t first = 0;
    if (!open_window(t, x.size(), t_start, "increment", est, first)) return est;
    est.t_first = t[first];
    est.t_last = t.back();
    est.slope = (x.back() - x[first]) / (est.t_last - est.t_first);
    est.t_mean = 0.5 * (est.t_first + est.t_last);
    est.ok = true;
    return est;
}

SlopeEstimate window_slope(SlopeFit fit, std::span<const double> t,
                           std::span<const Eigen::VectorXd> x, double t_start) {
    return fit == SlopeFit::increment ? increment_slope(t, x, t_start)
                                      : least_squares_slope(t, x, t_start);
}

double walk_slope_variance_factor(SlopeFit fit) {
    return fit == SlopeFit::increment ? 1.0 : 1.2;
}

LineFit fit_line(std::span<const double> t, std::span<const double> y) {
    EFDEM_EXPECTS(t.size() >= 2 && y.size() == t.size());
    EFDEM_EXPECTS(strictly_increasing(t));
    const Line<double> line = least_squares_line(t, y);
    return {line.slope, line.t_mean, line.mean};
}

Eigen::VectorXd interval_mean(std::span<const double> t, std::span<const Eigen::VectorXd> x,
                              double a, double b) {
    return interval_integral(t, x, a, b) / (b - a);
}

double interval_mean(std::span<const double> t, std::span<const double> y, double a, double b) {
    return interval_integral(t, y, a, b) / (b - a);
}

SlopeEstimate period_mean_slope(std::span<const double> t, std::span<const Eigen::VectorXd> x,
                                double period, double t_end) {
    EFDEM_EXPECTS(period > 0.0 && std::isfinite(period));
    EFDEM_EXPECTS(x.size() == t.size());
    EFDEM_EXPECTS(strictly_increasing(t));
    SlopeEstimate est;
    const double t0 = t_end - 2.0 * period;
    if (t.size() < 2 || t.front() > t0 + time_tolerance(t0) ||
        t.back() < t_end - time_tolerance(t_end)) {
        est.message = fmt::format(
            "period-mean slope needs samples covering two periods [{:.6g}, {:.6g}] (T = {:.6g}); "
            "the burst covers [{:.6g}, {:.6g}]",
            t0, t_end, period, t.empty() ? 0.0 : t.front(), t.empty() ? 0.0 : t.back());
        return est;
    }
    const Eigen::VectorXd earlier = interval_mean(t, x, t0, t_end - period);
    const Eigen::VectorXd last = interval_mean(t, x, t_end - period, t_end);
    est.slope = (last - earlier) / period;
    const auto first = t.begin() + static_cast<std::ptrdiff_t>(first_sample_at_or_after(t, t0));
    const auto past_end = std::upper_bound(first, t.end(), t_end + time_tolerance(t_end));
    est.n_samples = static_cast<Eigen::Index>(past_end - first);
    est.t_first = t0;
    est.t_last = t_end;
    est.ok = true;
    return est;
}

Eigen::MatrixXd member_least_squares_slopes(std::span<const double> t,
                                            std::span<const Eigen::MatrixXd> members,
                                            double t_start) {
    return slopes_per_member(t, members, [&](std::span<const Eigen::VectorXd> x) {
        return least_squares_slope(t, x, t_start);
    });
}

Eigen::MatrixXd member_window_slopes(SlopeFit fit, std::span<const double> t,
                                     std::span<const Eigen::MatrixXd> members, double t_start) {
    return slopes_per_member(t, members, [&](std::span<const Eigen::VectorXd> x) {
        return window_slope(fit, t, x, t_start);
    });
}

Eigen::MatrixXd member_period_mean_slopes(std::span<const double> t,
                                          std::span<const Eigen::MatrixXd> members, double period,
                                          double t_end) {
    return slopes_per_member(t, members, [&](std::span<const Eigen::VectorXd> x) {
        return period_mean_slope(t, x, period, t_end);
    });
}

Eigen::VectorXd slope_standard_error(const Eigen::MatrixXd& member_slopes) {
    const Eigen::Index n = member_slopes.rows();
    if (n < 2) return {};
    // Var(mean) = Var(s_r) / R with the unbiased Var(s_r) (divisor R - 1).
    const Eigen::VectorXd var = ensemble_variance(member_slopes, ensemble_mean(member_slopes));
    return (var / static_cast<double>(n)).cwiseSqrt();
}

Eigen::VectorXd member_slope_standard_error(std::span<const double> t,
                                            std::span<const Eigen::MatrixXd> members,
                                            double t_start) {
    return slope_standard_error(member_least_squares_slopes(t, members, t_start));
}

}  // namespace efdem::coarse
