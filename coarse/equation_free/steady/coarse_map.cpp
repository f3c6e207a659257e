#include "coarse/equation_free/steady/coarse_map.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "coarse/equation_free/ensemble_statistics.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

Eigen::MatrixXd CoarseCoordinates::rows_from_state(const Eigen::MatrixXd& rows) const {
    Eigen::MatrixXd out(rows.rows(), rows.cols());
    for (Eigen::Index r = 0; r < rows.rows(); ++r)
        out.row(r) = from_state(rows.row(r).transpose()).transpose();
    return out;
}

CoarseMap::CoarseMap(CoarseStepper& stepper, const CoarseMapSettings& settings,
                     std::function<void(double)> set_parameter)
    : stepper_(stepper), settings_(settings), set_parameter_(std::move(set_parameter)) {
    EFDEM_EXPECTS(settings_.tau > 0.0 && settings_.difference_step > 0.0);
    EFDEM_EXPECTS(!settings_.common_random_numbers || stepper_.can_keep_state());
}

MapEvaluation CoarseMap::run_once(const Eigen::VectorXd& x, double parameter) {
    EFDEM_EXPECTS(set_parameter_ || parameter == 0.0);
    if (set_parameter_) set_parameter_(parameter);
    Eigen::VectorXd lifted = coordinates_ ? coordinates_.to_state(x) : x;
    if (repair_) {
        const RepairReport report = repair_(lifted);
        EFDEM_ASSERT(report.feasible);
        if (report.changed()) {
            ++repairs_;
            largest_repair_ = std::max(largest_repair_, report.max_adjustment);
        }
    }
    stepper_.lift(lifted, stepper_.time());
    BurstSamples burst;
    stepper_.run(settings_.tau, burst);
    EFDEM_ASSERT(burst.size() >= 1 && burst.x.back().size() == lifted.size());
    micro_time_ += settings_.tau;
    ++evaluations_;
    MapEvaluation e;
    e.x = x;
    e.parameter = parameter;
    e.phi = coordinates_ ? coordinates_.from_state(burst.x.back()) : burst.x.back();
    EFDEM_ASSERT(e.phi.size() == x.size());
    e.f = e.phi - x;
    e.standard_error = Eigen::VectorXd::Zero(x.size());
    double state_noise = 0.0;
    if (!burst.members.empty() && burst.members.back().rows() >= 2) {
        const Eigen::MatrixXd& m = burst.members.back();
        e.standard_error = ensemble_standard_error(m);  // in X
        state_noise = e.standard_error.norm();
        e.members = coordinates_ ? coordinates_.rows_from_state(m) : m;
        if (coordinates_) e.standard_error = ensemble_standard_error(e.members);  // in u
    }
    e.noise_norm = e.standard_error.norm();
    // In X: Phi's restriction against the point the solver asked for (before any repair).
    e.state_residual_norm =
        coordinates_ ? (burst.x.back() - coordinates_.to_state(x)).norm() : e.f.norm();
    e.state_noise_norm = coordinates_ ? state_noise : e.noise_norm;
    return e;
}

const MapEvaluation& CoarseMap::begin(const Eigen::VectorXd& x, double parameter) {
    EFDEM_EXPECTS(!has_base_);
    if (settings_.common_random_numbers) stepper_.keep_state();
    base_ = run_once(x, parameter);
    has_base_ = true;
    return base_;
}

void CoarseMap::rewind() {
    if (!settings_.common_random_numbers) return;
    stepper_.return_to_kept_state();
    stepper_.keep_state();
}

MapEvaluation CoarseMap::evaluate_from_base(const Eigen::VectorXd& x, double parameter) {
    EFDEM_EXPECTS(has_base_ && x.size() == base_.x.size());
    rewind();
    return run_once(x, parameter);
}

Eigen::VectorXd CoarseMap::derivative(const Eigen::VectorXd& v, double dparameter) {
    EFDEM_EXPECTS(has_base_ && v.size() == base_.x.size());
    const double length = std::sqrt(v.squaredNorm() + dparameter * dparameter);
    if (length == 0.0) return Eigen::VectorXd::Zero(v.size());
    const double forward = base_.parameter + (settings_.difference_step / length) * dparameter;
    // Backwards where the forward point's parameter is one the micro model cannot run at.
    const double h =
        parameter_in_bounds(forward) ? settings_.difference_step : -settings_.difference_step;
    const MapEvaluation e =
        evaluate_from_base(base_.x + (h / length) * v, base_.parameter + (h / length) * dparameter);
    derivative_noise_ = 0.0;
    if (base_.members.rows() >= 2 && e.members.rows() == base_.members.rows()) {
        const Eigen::MatrixXd d = (e.members - base_.members) * (length / h);
        derivative_noise_ = ensemble_standard_error(d).norm();
    }
    return (e.phi - base_.phi) * (length / h);
}

void CoarseMap::end() {
    EFDEM_EXPECTS(has_base_);
    if (settings_.common_random_numbers) stepper_.confirm_kept_state();
    has_base_ = false;
}

MapEvaluation CoarseMap::evaluate(const Eigen::VectorXd& x, double parameter) {
    EFDEM_EXPECTS(!has_base_);
    return run_once(x, parameter);
}

}  // namespace efdem::coarse
