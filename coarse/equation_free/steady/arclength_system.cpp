#include "coarse/equation_free/steady/arclength_system.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include "core/contracts.hpp"
#include "core/log.hpp"

namespace efdem::coarse {

ArclengthSystem::ArclengthSystem(CoarseMap& map, Eigen::VectorXd tangent, Eigen::VectorXd predicted)
    : map_(map), tangent_(std::move(tangent)), predicted_(std::move(predicted)) {
    EFDEM_EXPECTS(map_.has_parameter() && tangent_.size() == predicted_.size() &&
                  tangent_.size() >= 2);
    EFDEM_EXPECTS(std::abs(tangent_.norm() - 1.0) < 1e-12);
    EFDEM_EXPECTS(map_.parameter_in_bounds(predicted_[predicted_.size() - 1]));
}

SystemEvaluation ArclengthSystem::assemble(const MapEvaluation& e, const Eigen::VectorXd& y) const {
    const Eigen::Index n = e.f.size();
    SystemEvaluation out;
    out.g.resize(n + 1);
    out.g.head(n) = e.f;
    out.g[n] = tangent_.dot(y - predicted_);
    out.noise_norm = e.noise_norm;
    out.state_residual = e.state_residual_norm;  // |F| of the point, without the arclength row
    out.state_noise = e.state_noise_norm;
    return out;
}

SystemEvaluation ArclengthSystem::begin(const Eigen::VectorXd& y) {
    EFDEM_EXPECTS(y.size() == dimension() && map_.parameter_in_bounds(y[y.size() - 1]));
    const Eigen::Index n = y.size() - 1;
    return assemble(map_.begin(y.head(n), y[n]), y);
}

Eigen::VectorXd ArclengthSystem::jacobian_times(const Eigen::VectorXd& v) {
    EFDEM_EXPECTS(v.size() == dimension());
    const Eigen::Index n = v.size() - 1;
    Eigen::VectorXd out(n + 1);
    out.head(n) = map_.derivative(v.head(n), v[n]) - v.head(n);
    out[n] = tangent_.dot(v);
    return out;
}

SystemEvaluation ArclengthSystem::trial(const Eigen::VectorXd& y) {
    EFDEM_EXPECTS(y.size() == dimension());
    const Eigen::Index n = y.size() - 1;
    if (!map_.parameter_in_bounds(y[n])) {  // not run: no decrease
        log::info("arclength trial at lambda = {:.6g} outside the parameter bounds: not evaluated",
                  y[n]);
        SystemEvaluation out;
        out.g = Eigen::VectorXd::Constant(n + 1, std::numeric_limits<double>::infinity());
        return out;
    }
    return assemble(map_.evaluate_from_base(y.head(n), y[n]), y);
}

}  // namespace efdem::coarse
