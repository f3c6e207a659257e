#include "coarse/equation_free/estimators/arrival_time.hpp"

#include <limits>

#include "core/contracts.hpp"

namespace efdem::coarse {

double arrival_time(const std::vector<double>& times, const std::vector<Eigen::VectorXd>& states,
                    const Eigen::VectorXd& target, double radius) {
    EFDEM_EXPECTS(times.size() == states.size() && radius >= 0.0);
    double since = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t k = states.size(); k-- > 0;) {
        const bool within =
            states[k].size() == target.size() && (states[k] - target).norm() <= radius;
        if (!within) break;
        since = times[k];
    }
    return since;
}

}  // namespace efdem::coarse
