#include "coarse/demixing/ensemble_observable.hpp"

#include <utility>

#include "coarse/demixing/monotone_repair.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

std::string EnsembleObservable::failure_reason() const {
    std::string why = failure_message();
    if (why.empty()) why = status_message();
    return why.empty() ? std::string("the restriction is not usable") : why;
}

Eigen::VectorXd IcdfObservable::restrict_ensemble(const Eigen::MatrixXd& icdf,
                                                  const Eigen::MatrixXd&) {
    EFDEM_EXPECTS(icdf.cols() == m_);
    return ensemble_mean(icdf);
}

Eigen::MatrixXd IcdfObservable::restrict_members(const Eigen::MatrixXd& icdf,
                                                 const Eigen::MatrixXd&) const {
    EFDEM_EXPECTS(icdf.cols() == m_);
    return icdf;
}

Eigen::VectorXd IcdfObservable::lift_target(const Eigen::VectorXd& x,
                                            const Eigen::VectorXd&) const {
    EFDEM_EXPECTS(x.size() == m_);
    return x;
}

RepairHook IcdfObservable::repair_hook(FeasibleRange range) const {
    return [range = std::move(range)](Eigen::VectorXd& x) {
        const auto [lo, hi] = range();
        return repair_monotone(x, lo, hi);
    };
}

}  // namespace efdem::coarse
