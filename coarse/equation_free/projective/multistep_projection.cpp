#include "coarse/equation_free/projective/multistep_projection.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

/// 3-point Gauss-Legendre on [t0, t0 + dt] of f: exact for polynomials of degree <= 5.
template <class F>
double gauss3(double t0, double dt, F f) {
    static constexpr std::array<double, 3> x{-0.7745966692414834, 0.0, 0.7745966692414834};
    static constexpr std::array<double, 3> w{5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) sum += w[i] * f(t0 + 0.5 * dt * (1.0 + x[i]));
    return 0.5 * dt * sum;
}

}  // namespace

std::vector<double> projection_weights(std::span<const SlopeNode> nodes, double t0, double dt) {
    EFDEM_EXPECTS(!nodes.empty() && nodes.size() <= 3 && dt >= 0.0);
    if (nodes.size() == 1) return {dt};
    std::vector<double> w;
    for (std::size_t k = 0; k < nodes.size(); ++k) {
        auto basis = [&](double t) {
            double l = 1.0;
            for (std::size_t j = 0; j < nodes.size(); ++j)
                if (j != k) l *= (t - nodes[j].tau) / (nodes[k].tau - nodes[j].tau);
            return l;
        };
        w.push_back(gauss3(t0, dt, basis));
    }
    return w;
}

Eigen::VectorXd projected_increment(std::span<const SlopeNode> nodes,
                                    std::span<const double> weights) {
    EFDEM_EXPECTS(weights.size() == nodes.size() && !nodes.empty());
    Eigen::VectorXd inc = weights[0] * nodes[0].slope;
    for (std::size_t k = 1; k < nodes.size(); ++k) inc += weights[k] * nodes[k].slope;
    return inc;
}

Eigen::VectorXd statistical_error(std::span<const SlopeNode> nodes,
                                  std::span<const double> weights) {
    EFDEM_EXPECTS(weights.size() == nodes.size() && !nodes.empty());
    Eigen::VectorXd var = Eigen::VectorXd::Zero(nodes[0].slope.size());
    for (std::size_t k = 0; k < nodes.size(); ++k) {
        EFDEM_EXPECTS(nodes[k].se.size() == var.size());
        var += (weights[k] * weights[k]) * nodes[k].se.cwiseAbs2();
    }
    return var.cwiseSqrt();
}

double omega_integral(std::span<const SlopeNode> nodes, double t0, double dt) {
    EFDEM_EXPECTS(!nodes.empty() && nodes.size() <= 2 && dt >= 0.0);
    return std::abs(gauss3(t0, dt, [&](double t) {
        double w = 1.0;
        for (const auto& n : nodes) w *= t - n.tau;
        return w;
    }));
}

namespace {
/// The divided difference's weight on node k: 1 / prod_{j != k} (tau_k - tau_j).
double divided_difference_weight(std::span<const SlopeNode> nodes, std::size_t k) {
    double denom = 1.0;
    for (std::size_t j = 0; j < nodes.size(); ++j)
        if (j != k) denom *= nodes[k].tau - nodes[j].tau;
    EFDEM_EXPECTS(denom != 0.0);
    return 1.0 / denom;
}

void set_debiased_norm(DividedDifference& d) {
    d.norm = debiased_rms(d.value, d.noise_variance);
}
}  // namespace

double debiased_rms(const Eigen::VectorXd& value, const Eigen::VectorXd& noise_variance) {
    const auto m = value.size();
    const double excess = value.squaredNorm() - noise_variance.sum();
    return m > 0 ? std::sqrt(std::max(0.0, excess / static_cast<double>(m))) : 0.0;
}

DividedDifference slope_divided_difference(std::span<const SlopeNode> nodes) {
    EFDEM_EXPECTS(nodes.size() >= 2);
    const Eigen::Index m = nodes[0].slope.size();
    DividedDifference d;
    d.value = Eigen::VectorXd::Zero(m);
    d.noise_variance = Eigen::VectorXd::Zero(m);
    for (std::size_t k = 0; k < nodes.size(); ++k) {
        EFDEM_EXPECTS(nodes[k].slope.size() == m && nodes[k].se.size() == m);
        const double c = divided_difference_weight(nodes, k);
        d.value += c * nodes[k].slope;
        d.noise_variance += (c * c) * nodes[k].se.cwiseAbs2();
    }
    set_debiased_norm(d);
    return d;
}

DividedDifference curvature_left(std::span<const SlopeNode> nodes, const PooledCurvature& b) {
    DividedDifference d = slope_divided_difference(nodes);
    EFDEM_EXPECTS(b.value.size() == d.value.size());
    Eigen::VectorXd cov = Eigen::VectorXd::Zero(d.value.size());  // Cov(d, b)
    for (std::size_t k = 0; k < nodes.size(); ++k)
        for (std::size_t j = 0; j < b.tau.size(); ++j)
            if (b.tau[j] == nodes[k].tau)
                cov += divided_difference_weight(nodes, k) *
                       b.cov_slopes.row(static_cast<Eigen::Index>(j)).transpose();
    d.value -= b.value;
    d.noise_variance = (d.noise_variance + b.variance - 2.0 * cov).cwiseMax(0.0);
    set_debiased_norm(d);
    return d;
}

double rms(const Eigen::VectorXd& v) {
    return v.size() == 0 ? 0.0 : std::sqrt(v.squaredNorm() / static_cast<double>(v.size()));
}

}  // namespace efdem::coarse
