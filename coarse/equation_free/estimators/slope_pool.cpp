#include "coarse/equation_free/estimators/slope_pool.hpp"

#include <cmath>
#include <utility>

#include "core/contracts.hpp"

namespace efdem::coarse {

std::string_view to_string(SlopeSource source) {
    return source == SlopeSource::pooled ? "pooled" : "burst";
}

SlopePool::SlopePool(std::size_t capacity) : capacity_(capacity) {
    EFDEM_EXPECTS(capacity >= 1);
}

void SlopePool::add(const SlopeNode& node) {
    EFDEM_EXPECTS(node.se.size() == node.slope.size());
    EFDEM_EXPECTS(bursts_.empty() || node.slope.size() == bursts_.front().node.slope.size());
    bursts_.push_back({node, 0.0});
    while (bursts_.size() > capacity_) bursts_.pop_front();
}

PooledSlope SlopePool::estimate(std::size_t m) const {
    EFDEM_EXPECTS(m >= 1 && m <= bursts_.size());
    const auto first = bursts_.end() - static_cast<std::ptrdiff_t>(m);
    // Inverse-variance weights, one per burst; equal weights when a burst's noise is not known
    // (zero or not finite: a run without members), where 1/v would single it out.
    std::vector<double> w;
    w.reserve(m);
    bool all_known = true;
    for (auto it = first; it != bursts_.end(); ++it) {
        const double v = it->node.se.size()
                             ? it->node.se.squaredNorm() / static_cast<double>(it->node.se.size())
                             : 0.0;
        const bool known = v > 0.0 && std::isfinite(v);
        all_known = all_known && known;
        w.push_back(known ? 1.0 / v : 1.0);
    }
    if (!all_known) w.assign(m, 1.0);
    double sum = 0.0;
    for (double x : w) sum += x;
    for (double& x : w) x /= sum;

    PooledSlope e;
    const Eigen::Index dim = first->node.slope.size();
    e.node.slope = Eigen::VectorXd::Zero(dim);
    Eigen::VectorXd var = Eigen::VectorXd::Zero(dim);
    e.committed = Eigen::VectorXd::Zero(dim);
    std::size_t k = 0;
    for (auto it = first; it != bursts_.end(); ++it, ++k) {
        e.node.tau += w[k] * it->node.tau;
        e.node.slope += w[k] * it->node.slope;
        const Eigen::VectorXd se2 = it->node.se.cwiseAbs2();
        var += (w[k] * w[k]) * se2;
        e.committed += (w[k] * it->commitment) * se2;
    }
    e.node.se = var.cwiseSqrt();
    e.weights = std::move(w);
    return e;
}

Eigen::VectorXd charged_error(const Eigen::VectorXd& se, const Eigen::VectorXd& committed,
                              double dt) {
    EFDEM_EXPECTS(dt >= 0.0 && se.size() == committed.size());
    return (dt * dt * se.array().square() + 2.0 * dt * committed.array()).max(0.0).sqrt().matrix();
}

void SlopePool::commit(const PooledSlope& e, double dt) {
    EFDEM_EXPECTS(dt >= 0.0 && e.bursts() >= 1 && e.bursts() <= bursts_.size());
    add_commitments(e.weights, dt);
}

void SlopePool::add_commitments(std::span<const double> weights, double scale) {
    EFDEM_EXPECTS(weights.size() <= bursts_.size());
    auto it = bursts_.end() - static_cast<std::ptrdiff_t>(weights.size());
    for (double w : weights) (it++)->commitment += scale * w;
}

void SlopePool::restore(std::deque<PooledBurst> bursts) {
    EFDEM_EXPECTS(bursts.size() <= capacity_);
    bursts_ = std::move(bursts);
}

}  // namespace efdem::coarse
