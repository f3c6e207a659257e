#include "coarse/equation_free/estimators/pooled_curvature.hpp"

#include "core/contracts.hpp"

namespace efdem::coarse {

PooledCurvature pooled_curvature(std::span<const SlopeNode> nodes) {
    EFDEM_EXPECTS(nodes.size() >= 2);
    const Eigen::Index m = nodes.front().slope.size();
    const auto n = static_cast<Eigen::Index>(nodes.size());
    PooledCurvature out;
    out.value = Eigen::VectorXd::Zero(m);
    out.variance = Eigen::VectorXd::Zero(m);
    out.cov_slopes = Eigen::MatrixXd::Zero(n, m);
    double tau_mean = 0.0;
    for (const SlopeNode& k : nodes) {
        EFDEM_EXPECTS(k.slope.size() == m && k.se.size() == m && (k.se.array() >= 0.0).all());
        out.tau.push_back(k.tau);
        tau_mean += k.tau / static_cast<double>(n);
    }
    double stt = 0.0;
    for (const SlopeNode& k : nodes) stt += (k.tau - tau_mean) * (k.tau - tau_mean);
    EFDEM_EXPECTS(stt > 0.0);  // distinct taus
    for (Eigen::Index k = 0; k < n; ++k) {
        const SlopeNode& node = nodes[static_cast<std::size_t>(k)];
        const double c = (node.tau - tau_mean) / stt;
        const Eigen::VectorXd se2 = node.se.cwiseAbs2();
        out.weights.push_back(c);
        out.value += c * node.slope;
        out.variance += (c * c) * se2;
        out.cov_slopes.row(k) = (c * se2).transpose();
    }
    return out;
}

Eigen::VectorXd committed_covariance(const PooledCurvature& b,
                                     std::span<const double> commitments) {
    EFDEM_EXPECTS(commitments.size() == b.bursts());
    Eigen::VectorXd kappa = Eigen::VectorXd::Zero(b.cov_slopes.cols());
    for (std::size_t k = 0; k < commitments.size(); ++k)
        kappa += commitments[k] * b.cov_slopes.row(static_cast<Eigen::Index>(k)).transpose();
    return kappa;
}

}  // namespace efdem::coarse
