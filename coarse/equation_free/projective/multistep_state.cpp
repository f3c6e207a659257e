#include "coarse/equation_free/projective/multistep_state.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>

namespace efdem::coarse {

namespace {
bool same(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return a.size() == b.size() && (a.array() == b.array()).all();
}

bool same(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
    return a.rows() == b.rows() && a.cols() == b.cols() && (a.array() == b.array()).all();
}

bool same(const SlopeNode& a, const SlopeNode& b) {
    return a.tau == b.tau && same(a.slope, b.slope) && same(a.se, b.se);
}

/// Equal, or both NaN (the "not written" of optional values).
bool same_or_nan(double a, double b) {
    return a == b || (std::isnan(a) && std::isnan(b));
}
}  // namespace

bool MultistepState::operator==(const MultistepState& o) const {
    if (history.size() != o.history.size() || pool.size() != o.pool.size()) return false;
    for (std::size_t i = 0; i < history.size(); ++i)
        if (!same(history[i], o.history[i])) return false;
    for (std::size_t i = 0; i < pool.size(); ++i)
        if (!same(pool[i].node, o.pool[i].node) || pool[i].commitment != o.pool[i].commitment)
            return false;
    const DecayRateEstimate &d = decay, &e = o.decay;
    const MultistepTotals &t = totals, &u = o.totals;
    return t_end == o.t_end && same(x_end, o.x_end) &&
           curvature_only_front == o.curvature_only_front && d.ok == e.ok && d.rate == e.rate &&
           d.ratio == e.ratio && d.delay == e.delay && d.message == e.message &&
           hold_kind == o.hold_kind && hold == o.hold &&
           controller.dt_last == o.controller.dt_last && controller.dt_cap == o.controller.dt_cap &&
           controller.consecutive_rejections == o.controller.consecutive_rejections &&
           t.attempts == u.attempts && t.accepted == u.accepted && t.rejected == u.rejected &&
           t.direct == u.direct && t.dt_taken == u.dt_taken && t.dt_tolerance == u.dt_tolerance &&
           t.dt_tolerance_2r == u.dt_tolerance_2r && t.dt_tolerance_4r == u.dt_tolerance_4r &&
           t.statistical == u.statistical && t.truncation == u.truncation &&
           same_or_nan(healing, o.healing) && same_or_nan(lift_reserve, o.lift_reserve) &&
           same_or_nan(window, o.window) && same_or_nan(window_fast_time2, o.window_fast_time2) &&
           window_measurements == o.window_measurements && realizations == o.realizations &&
           same(member_deviation, o.member_deviation) &&
           same_or_nan(budget.variance, o.budget.variance) &&
           same_or_nan(budget.truncation, o.budget.truncation) &&
           same_or_nan(budget.t_last, o.budget.t_last) &&
           same_or_nan(budget.sigma, o.budget.sigma) &&
           same_or_nan(budget.last_rate, o.budget.last_rate) && budget.rate == o.budget.rate;
}

MultistepState MultistepState::from_layout(const std::vector<double>& r, const std::string& text) {
    auto malformed = [](const std::string& why) {
        return std::invalid_argument("the integrator state of a format 2/3 checkpoint " + why);
    };
    if (r.size() < 11 || (r[0] != 2.0 && r[0] != 3.0))
        throw malformed("has no known layout (2 or 3)");
    const auto n = static_cast<std::size_t>(r[1]);
    const auto m = static_cast<Eigen::Index>(r[2]);
    // Layout 2 lacks the last value: no curvature-only node.
    const std::size_t layout_extra = r[0] == 3.0 ? 1 : 0;
    if (r.size() != 11 + static_cast<std::size_t>(m) * (1 + 2 * n) + n + 10 + layout_extra)
        throw malformed("has the wrong length");
    MultistepState s;
    s.t_end = r[3];
    s.controller = {
        .dt_last = r[4], .dt_cap = r[5], .consecutive_rejections = static_cast<long>(r[6])};
    s.decay.ok = r[7] != 0.0;
    s.decay.rate = r[8];
    s.decay.ratio = r[9];
    s.decay.delay = r[10];
    // Three lines: the decay estimate's message, then why no jump may start here (kind, text).
    const std::size_t a = text.find('\n'), b = a == std::string::npos ? a : text.find('\n', a + 1);
    if (b == std::string::npos) throw malformed("text has fewer than three lines");
    s.decay.message = text.substr(0, a);
    const std::optional<DtLimit> kind = dt_limit_from_string(text.substr(a + 1, b - a - 1));
    if (!kind) throw malformed("names an unknown hold kind");
    s.hold_kind = *kind;
    s.hold = text.substr(b + 1);
    std::size_t k = 11;
    auto vec = [&] {
        Eigen::VectorXd v = Eigen::Map<const Eigen::VectorXd>(r.data() + k, m);
        k += static_cast<std::size_t>(m);
        return v;
    };
    s.x_end = vec();
    for (std::size_t i = 0; i < n; ++i) {
        SlopeNode node;
        node.tau = r[k++];
        node.slope = vec();
        node.se = vec();
        s.history.push_back(std::move(node));
    }
    MultistepTotals& t = s.totals;
    t.attempts = static_cast<long>(r[k]);
    t.accepted = static_cast<long>(r[k + 1]);
    t.rejected = static_cast<long>(r[k + 2]);
    t.direct = static_cast<long>(r[k + 3]);
    t.dt_taken = r[k + 4];
    t.dt_tolerance = r[k + 5];
    t.dt_tolerance_2r = r[k + 6];
    t.dt_tolerance_4r = r[k + 7];
    t.statistical = r[k + 8];
    t.truncation = r[k + 9];
    if (layout_extra) s.curvature_only_front = r[k + 10] != 0.0;
    return s;
}

}  // namespace efdem::coarse
