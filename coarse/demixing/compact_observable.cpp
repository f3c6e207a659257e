#include "coarse/demixing/compact_observable.hpp"

#include <limits>

#include "core/contracts.hpp"

namespace efdem::coarse {

Eigen::VectorXd CompactObservable::restrict_ensemble(const Eigen::MatrixXd& icdf,
                                                     const Eigen::MatrixXd& top) {
    EFDEM_EXPECTS(icdf.cols() == grid_.size() && top.cols() == grid_.size() &&
                  icdf.rows() == top.rows());
    const Eigen::VectorXd y = ensemble_mean(top) - ensemble_mean(icdf);
    last_ = fit_compact(y, grid_, previous_, settings_);
    // Full demixing (y = 0) has nothing left to project with (A, B, C, D): the rule is
    // to fall back to the full ICDF with a message, as for a fit that failed.
    const bool usable =
        last_.status == CompactFitStatus::ok || last_.status == CompactFitStatus::ill_conditioned;
    if (!usable) {
        last_failure_ = last_.message;
        return Eigen::VectorXd::Constant(4, std::numeric_limits<double>::quiet_NaN());
    }
    previous_ = last_.parameters;
    return last_.parameters.vector();
}

Eigen::VectorXd CompactObservable::lift_target(const Eigen::VectorXd& x,
                                               const Eigen::VectorXd& top) const {
    EFDEM_EXPECTS(x.size() == 4 && top.size() == grid_.size());
    return light_icdf_from_compact(top, CompactParameters::from_vector(x), grid_);
}

std::vector<double> CompactObservable::saved_state() const {
    if (!previous_) return {};
    return {previous_->a, previous_->b, previous_->c, previous_->d};
}

void CompactObservable::restore_state(const std::vector<double>& state) {
    EFDEM_EXPECTS(state.empty() || state.size() == 4);
    if (state.empty())
        previous_.reset();
    else
        previous_ = CompactParameters{state[0], state[1], state[2], state[3]};
}

}  // namespace efdem::coarse
