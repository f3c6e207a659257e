#include "coarse/demixing/rank_observable.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "coarse/demixing/monotone_repair.hpp"
#include "coarse/demixing/whole_bed_profile.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

Eigen::VectorXd RankObservable::restrict_ensemble(const Eigen::MatrixXd& icdf,
                                                  const Eigen::MatrixXd& profiles) {
    EFDEM_EXPECTS(icdf.cols() == m_ && profiles.cols() == kWholeBedNodes &&
                  icdf.rows() == profiles.rows());
    // The rows are the realizations in use: every profile is finite.
    EFDEM_EXPECTS(profiles.rows() > 0 && profiles.allFinite());
    if (reference_.size() == 0)
        reference_ = ensemble_mean(profiles);  // a mean of non-decreasing profiles is one too
    return ensemble_mean(restrict_members(icdf, profiles));
}

Eigen::MatrixXd RankObservable::restrict_members(const Eigen::MatrixXd& icdf,
                                                 const Eigen::MatrixXd& profiles) const {
    EFDEM_EXPECTS(reference_.size() == kWholeBedNodes);
    EFDEM_EXPECTS(icdf.cols() == m_ && profiles.cols() == kWholeBedNodes &&
                  icdf.rows() == profiles.rows());
    Eigen::MatrixXd out(icdf.rows(), m_);
    for (Eigen::Index r = 0; r < icdf.rows(); ++r) {
        const Eigen::VectorXd q = icdf.row(r).transpose();
        const Eigen::VectorXd profile = profiles.row(r).transpose();
        if (!q.allFinite() || !profile.allFinite()) {
            out.row(r).setConstant(std::numeric_limits<double>::quiet_NaN());
            continue;
        }
        out.row(r) = heights_at(ranks_in(q, profile), reference_).transpose();
    }
    return out;
}

Eigen::VectorXd RankObservable::lift_target(const Eigen::VectorXd& x,
                                            const Eigen::VectorXd& profile) const {
    EFDEM_EXPECTS(reference_.size() == kWholeBedNodes);
    EFDEM_EXPECTS(x.size() == m_ && profile.size() == kWholeBedNodes);
    return heights_at(ranks_in(x, reference_), profile);
}

RepairHook RankObservable::repair_hook(FeasibleRange) const {
    return [this](Eigen::VectorXd& x) {
        EFDEM_EXPECTS(reference_.size() == kWholeBedNodes);
        const Eigen::VectorXd original = x;
        RepairReport report = repair_monotone(x, reference_[0], reference_[kWholeBedNodes - 1]);
        if (!report.feasible || std::isnan(observed_fraction_)) return report;
        const RepairReport counts = repair_light_counts(x);
        if (!counts.changed()) return report;
        report.max_adjustment = (x - original).cwiseAbs().maxCoeff();
        report.message += (report.message.empty() ? "" : "; ") + counts.message;
        return report;
    };
}

RepairReport RankObservable::repair_light_counts(Eigen::VectorXd& x) const {
    const double phi = observed_fraction_;
    // y_i = u_i - phi p_i: the particles below node i less the lights below it, per particle.
    Eigen::VectorXd y = ranks_in(x, reference_) - phi * p_;
    // A violation below half a bin of the profile (0.005 of the bed) is the resolution of its
    // linear map: a sampled pure-light stretch read through it breaks the limit by about
    // sqrt(n)/(2N) with n = N/100 particles per bin (0.0016 for N = 1,000, measured up to 0.0033
    // in tests/coarse/test_rank_observable.cpp; 0.0009 for 3,120). Only a larger one, a
    // projection's (0.006-0.022 on the tall bed's jumps of 11-22 units), starts the repair.
    constexpr double kMapResolution = 0.5 / static_cast<double>(kWholeBedNodes - 1);
    int n_over =
        (y[0] < -kMapResolution ? 1 : 0) + (y[m_ - 1] > 1.0 - phi + kMapResolution ? 1 : 0);
    for (Eigen::Index i = 1; i < m_; ++i) n_over += y[i] < y[i - 1] - kMapResolution ? 1 : 0;
    if (n_over == 0) return {};
    const Eigen::VectorXd y_in = y;
    repair_monotone(y, 0.0, 1.0 - phi);
    const Eigen::VectorXd moved = heights_at(y + phi * p_, reference_);
    const Eigen::VectorXd before = x;
    for (Eigen::Index i = 0; i < m_; ++i)
        if (y[i] != y_in[i]) x[i] = moved[i];
    RepairReport report;
    report.max_adjustment = (x - before).cwiseAbs().maxCoeff();
    report.message = fmt::format(
        "{} interval(s) asked for more light particles than the bed has there (observed "
        "fraction {:.4g}): ranks projected onto the liftable set, largest change {:.3g}",
        n_over, phi, report.max_adjustment);
    return report;
}

void RankObservable::set_observed_fraction(double fraction) {
    EFDEM_EXPECTS(std::isnan(fraction) || (fraction > 0.0 && fraction <= 1.0));
    observed_fraction_ = fraction;
}

std::vector<double> RankObservable::saved_state() const {
    if (reference_.size() == 0) return {};
    std::vector<double> state(reference_.data(), reference_.data() + reference_.size());
    state.push_back(observed_fraction_);
    return state;
}

void RankObservable::restore_state(const std::vector<double>& state) {
    const auto n = static_cast<Eigen::Index>(state.size());
    EFDEM_EXPECTS(n == 0 || n == kWholeBedNodes || n == kWholeBedNodes + 1);
    reference_ = Eigen::Map<const Eigen::VectorXd>(state.data(), std::min(n, kWholeBedNodes));
    observed_fraction_ =
        n == kWholeBedNodes + 1 ? state.back() : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace efdem::coarse
