#include "coarse/equation_free/estimators/post_lift_transient.hpp"

#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

MeanSignificance post_lift_transient(std::span<const double> t,
                                     std::span<const Eigen::MatrixXd> members, double t_lift) {
    EFDEM_EXPECTS(members.size() == t.size());
    if (t.empty()) return {};
    const std::size_t first = first_sample_at_or_after(t, t_lift + time_tolerance(t_lift) * 2);
    const double t_mid = 0.5 * (t_lift + t.back());
    const std::size_t late = first_sample_at_or_after(t, t_mid);
    if (late < first + 2 || t.size() < late + 2 || members[first].rows() < 2) return {};
    // Each realization's late line: its slope over [t_mid, t_last] and its mean there.
    const Eigen::MatrixXd slopes = member_least_squares_slopes(t, members, t_mid);
    if (slopes.rows() == 0) return {};
    auto mean_over = [&](std::size_t a, std::size_t b, Eigen::MatrixXd& x, double& tm) {
        x = Eigen::MatrixXd::Zero(members[a].rows(), members[a].cols());
        tm = 0.0;
        for (std::size_t k = a; k < b; ++k) {
            x += members[k];
            tm += t[k];
        }
        x /= static_cast<double>(b - a);
        tm /= static_cast<double>(b - a);
    };
    Eigen::MatrixXd early_mean, late_mean;
    double t_early = 0.0, t_late = 0.0;
    mean_over(first, late, early_mean, t_early);
    mean_over(late, t.size(), late_mean, t_late);
    // The mean residual of a line over the early samples is the residual at their mean time.
    const Eigen::MatrixXd residual = early_mean - late_mean - (t_early - t_late) * slopes;
    return mean_significance(residual);
}

}  // namespace efdem::coarse
