#include "coarse/demixing/rank_observable.hpp"

#include <limits>
#include <utility>

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
        return repair_monotone(x, reference_[0], reference_[kWholeBedNodes - 1]);
    };
}

std::vector<double> RankObservable::saved_state() const {
    return {reference_.data(), reference_.data() + reference_.size()};
}

void RankObservable::restore_state(const std::vector<double>& state) {
    EFDEM_EXPECTS(state.empty() || static_cast<Eigen::Index>(state.size()) == kWholeBedNodes);
    reference_ =
        Eigen::Map<const Eigen::VectorXd>(state.data(), static_cast<Eigen::Index>(state.size()));
}

}  // namespace efdem::coarse
