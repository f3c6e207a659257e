#include "coarse/demixing/icdf_gap_coordinates.hpp"

#include <algorithm>
#include <cmath>

#include "core/contracts.hpp"

namespace efdem::coarse {

CoarseCoordinates icdf_gap_coordinates(double floor) {
    EFDEM_EXPECTS(floor > 0.0);
    CoarseCoordinates c;
    c.name = "gaps";
    c.to_state = [](const Eigen::VectorXd& u) {
        Eigen::VectorXd x(u.size());
        for (Eigen::Index i = 0; i < u.size(); ++i)
            x[i] = i == 0 ? u[0] : x[i - 1] + std::exp(u[i]);
        return x;
    };
    c.from_state = [floor](const Eigen::VectorXd& x) {
        Eigen::VectorXd u(x.size());
        for (Eigen::Index i = 0; i < x.size(); ++i)
            u[i] = i == 0 ? x[0] : std::log(std::max(x[i] - x[i - 1], floor));
        return u;
    };
    return c;
}

}  // namespace efdem::coarse
