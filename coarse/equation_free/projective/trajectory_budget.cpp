#include "coarse/equation_free/projective/trajectory_budget.hpp"

#include <algorithm>
#include <cmath>

#include "coarse/equation_free/ensemble_statistics.hpp"
#include "coarse/equation_free/projective/multistep_projection.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

double walk_rate(const SlopeNode& burst, double window, SlopeFit fit) {
    if (window <= 0.0 || burst.se.size() == 0) return 0.0;
    return window * burst.se.squaredNorm() / static_cast<double>(burst.se.size()) /
           walk_slope_variance_factor(fit);
}

TrajectoryBudget::TrajectoryBudget(double accuracy) : accuracy_(accuracy) {
    EFDEM_EXPECTS(std::isfinite(accuracy) && accuracy > 0.0);
}

double TrajectoryBudget::standard_error(const Eigen::MatrixXd& members) {
    if (members.rows() < 2 || members.cols() == 0) return std::numeric_limits<double>::quiet_NaN();
    return rms(ensemble_standard_error(members));
}

double TrajectoryBudget::standard_error(const BurstSamples& burst, double t_from) {
    if (burst.members.size() != burst.t.size()) return std::numeric_limits<double>::quiet_NaN();
    const double eps = 1e-9 * std::max(1.0, std::abs(t_from));
    double sum = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < burst.t.size(); ++i) {
        if (burst.t[i] < t_from - eps) continue;
        const double s = standard_error(burst.members[i]);
        if (!std::isfinite(s)) continue;
        sum += s * s;
        ++n;
    }
    return n > 0 ? std::sqrt(sum / n) : std::numeric_limits<double>::quiet_NaN();
}

void TrajectoryBudget::measure(double sigma) {
    EFDEM_EXPECTS(std::isfinite(sigma) && sigma >= 0.0);
    state_.sigma = sigma;
}

bool TrajectoryBudget::ready() const {
    return std::isfinite(state_.sigma);
}

double TrajectoryBudget::budget() const {
    return accuracy_ * state_.sigma;
}

double TrajectoryBudget::spent(double t) const {
    if (std::isnan(state_.t_last)) return 0.0;
    const double decay = std::exp(-state_.rate * std::max(0.0, t - state_.t_last));
    return (state_.truncation + std::sqrt(state_.variance)) * decay;
}

void TrajectoryBudget::credit(double measured, double cap) {
    EFDEM_EXPECTS(cap > 0.0);
    const bool now = std::isfinite(measured) && measured > 0.0;
    const bool before = std::isfinite(state_.last_rate) && state_.last_rate > 0.0;
    state_.rate = now && before ? std::min({measured, state_.last_rate, cap}) : 0.0;
    state_.last_rate = now ? measured : std::numeric_limits<double>::quiet_NaN();
}

double TrajectoryBudget::jump_tolerance(const JumpErrorModel& model, double end_time, double burst,
                                        double dt_max, double walk) const {
    EFDEM_EXPECTS(ready() && burst > 0.0 && std::isfinite(dt_max) && dt_max > 0.0 &&
                  std::isfinite(end_time) && end_time > model.t0 && std::isfinite(walk) &&
                  walk >= 0.0);
    const double h = end_time - model.t0;
    const double since = std::isnan(state_.t_last) ? 0.0 : std::max(0.0, model.t0 - state_.t_last);
    const double d = std::exp(-state_.rate * since);  // what has decayed by now, not later
    const double t_now = state_.truncation * d, v_now = state_.variance * d * d;
    const double b = budget();
    const auto at_end = [&](double dt) {
        const JumpError e = jump_error(model, dt);
        const double n = h / (dt + burst);
        return t_now + n * e.truncation +
               std::sqrt(v_now + n * (e.statistical * e.statistical + dt * walk));
    };
    const double cap = std::min(dt_max, h);
    if (at_end(0.0) > b) return 0.0;  // spent: no jump fits
    double lo = 0.0, hi = cap;        // at_end(lo) <= b
    if (at_end(hi) <= b) {
        lo = hi;
    } else {
        while (hi - lo > 1e-6 * hi) {
            const double mid = 0.5 * (lo + hi);
            (at_end(mid) <= b ? lo : hi) = mid;
        }
    }
    return jump_error(model, lo).total();
}

void TrajectoryBudget::commit(double t_landed, double statistical, double truncation, double walk) {
    EFDEM_EXPECTS(statistical >= 0.0 && truncation >= 0.0 && walk >= 0.0);
    if (!std::isnan(state_.t_last)) {
        const double decay = std::exp(-state_.rate * std::max(0.0, t_landed - state_.t_last));
        state_.variance *= decay * decay;
        state_.truncation *= decay;
    }
    state_.variance += statistical * statistical + walk;
    state_.truncation += truncation;
    state_.t_last = t_landed;
}

}  // namespace efdem::coarse
