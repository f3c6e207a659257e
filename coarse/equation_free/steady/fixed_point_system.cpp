#include "coarse/equation_free/steady/fixed_point_system.hpp"

#include "core/contracts.hpp"

namespace efdem::coarse {

SystemEvaluation FixedPointSystem::begin(const Eigen::VectorXd& y) {
    EFDEM_EXPECTS(y.size() == n_);
    const MapEvaluation& e = map_.begin(y, parameter_);
    return {e.f, e.noise_norm, e.state_residual_norm, e.state_noise_norm};
}

SystemEvaluation FixedPointSystem::trial(const Eigen::VectorXd& y) {
    EFDEM_EXPECTS(y.size() == n_);
    const MapEvaluation e = map_.evaluate_from_base(y, parameter_);
    return {e.f, e.noise_norm, e.state_residual_norm, e.state_noise_norm};
}

}  // namespace efdem::coarse
