#include "coarse/equation_free/estimators/window_noise.hpp"

#include <algorithm>
#include <cmath>

#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

/// The members' slopes about their ensemble mean (R x dim), over samples [a, b).
Eigen::MatrixXd slope_deviations(std::span<const double> t,
                                 std::span<const Eigen::MatrixXd> members, std::size_t a,
                                 std::size_t b) {
    Eigen::MatrixXd s =
        member_least_squares_slopes(t.subspan(a, b - a), members.subspan(a, b - a), t[a]);
    if (s.rows() == 0) return s;
    s.rowwise() -= s.colwise().mean();
    return s;
}

}  // namespace

WindowNoise window_noise(std::span<const double> t, std::span<const Eigen::MatrixXd> members,
                         double t_window) {
    EFDEM_EXPECTS(members.size() == t.size());
    WindowNoise out;
    const std::size_t first = first_sample_at_or_after(t, t_window);
    if (t.size() < first + 4 || members[first].rows() < 2) return out;
    const double t_mid = 0.5 * (t[first] + t.back());
    const std::size_t mid = first_sample_at_or_after(t, t_mid);
    if (mid < first + 2 || t.size() < mid + 2) return out;
    const Eigen::MatrixXd whole = slope_deviations(t, members, first, t.size());
    const Eigen::MatrixXd early = slope_deviations(t, members, first, mid);
    const Eigen::MatrixXd late = slope_deviations(t, members, mid, t.size());
    if (whole.rows() == 0 || early.rows() == 0 || late.rows() == 0) return out;
    const double v_whole = whole.squaredNorm(), v_early = early.squaredNorm(),
                 v_late = late.squaredNorm();
    if (!(v_whole > 0.0) || !(v_early > 0.0) || !(v_late > 0.0)) return out;
    out.measured = true;
    out.window = t.back() - t[first];
    out.ratio = 0.5 * (v_early + v_late) / v_whole;
    out.correlation = (early.array() * late.array()).sum() / std::sqrt(v_early * v_late);
    // Not clamped below: a mean over bursts of values clamped at 0 would count noise as fast.
    const double rho = std::min(out.ratio, 7.5);
    out.fast_time2 = (rho - 2.0) / (8.0 - rho) * out.window * out.window;
    return out;
}

double window_inefficiency(double window, double healing, double fast_time2) {
    EFDEM_EXPECTS(window > 0.0 && healing >= 0.0);
    const double u = std::max(fast_time2, 0.0) / (window * window);
    return healing / window + u * (1.0 + healing / window);
}

double efficient_window(double healing, double fast_time2, double limit, double lo, double hi,
                        double step) {
    EFDEM_EXPECTS(lo > 0.0 && lo <= hi && step > 0.0 && limit > 0.0);
    // g falls monotonically in W: the first grid window within the limit.
    const auto n = static_cast<long>(std::floor((hi - lo) / step + 1e-9));
    for (long k = 0; k <= n; ++k) {
        const double w = lo + static_cast<double>(k) * step;
        if (window_inefficiency(w, healing, fast_time2) <= limit) return w;
    }
    return hi;
}

}  // namespace efdem::coarse
