#include "coarse/equation_free/estimators/drift_test.hpp"

#include <cmath>
#include <limits>

#include "core/contracts.hpp"

namespace efdem::coarse {

DriftTest::DriftTest(std::size_t bursts, int confirmations)
    : bursts_(bursts), confirmations_(confirmations) {
    EFDEM_EXPECTS(bursts >= 2 && confirmations >= 1);
}

void DriftTest::add(const SlopeNode& node) {
    EFDEM_EXPECTS(node.slope.size() == node.se.size());
    const bool usable = node.slope.size() > 0 && node.slope.allFinite() && node.se.allFinite() &&
                        (node.se.array() > 0).all();
    if (!usable) {
        clear();
        return;
    }
    if (!nodes_.empty() && nodes_.front().slope.size() != node.slope.size()) clear();
    nodes_.push_back(node);
    if (nodes_.size() > bursts_) nodes_.pop_front();
    if (!ready()) return;
    quiet_ = z() <= kSteadyZ ? quiet_ + 1 : 0;
}

void DriftTest::clear() {
    nodes_.clear();
    quiet_ = 0;
}

double DriftTest::z() const {
    if (!ready()) return std::numeric_limits<double>::quiet_NaN();
    double inverse_sum = 0;
    for (const SlopeNode& n : nodes_) inverse_sum += 1.0 / n.se.array().square().mean();
    const Eigen::Index m = nodes_.front().slope.size();
    Eigen::VectorXd s = Eigen::VectorXd::Zero(m), var = Eigen::VectorXd::Zero(m);
    for (const SlopeNode& n : nodes_) {
        const double w = (1.0 / n.se.array().square().mean()) / inverse_sum;
        s += w * n.slope;
        var += (w * w) * n.se.array().square().matrix();
    }
    return std::sqrt((s.array().square() / var.array()).mean());
}

double DriftTest::since() const {
    return nodes_.empty() ? std::numeric_limits<double>::quiet_NaN() : nodes_.front().tau;
}

std::vector<double> DriftTest::save() const {
    if (nodes_.empty()) return {};
    const auto m = static_cast<std::size_t>(nodes_.front().slope.size());
    std::vector<double> out{static_cast<double>(quiet_), static_cast<double>(m)};
    for (const SlopeNode& n : nodes_) {
        out.push_back(n.tau);
        out.insert(out.end(), n.slope.data(), n.slope.data() + m);
        out.insert(out.end(), n.se.data(), n.se.data() + m);
    }
    return out;
}

void DriftTest::restore(const std::vector<double>& state) {
    clear();
    if (state.empty()) return;
    EFDEM_EXPECTS(state.size() >= 2);
    quiet_ = static_cast<int>(state[0]);
    const auto m = static_cast<std::size_t>(state[1]);
    const std::size_t row = 1 + 2 * m;
    EFDEM_EXPECTS(m > 0 && (state.size() - 2) % row == 0);
    for (std::size_t k = 2; k < state.size(); k += row) {
        SlopeNode n;
        n.tau = state[k];
        n.slope = Eigen::Map<const Eigen::VectorXd>(&state[k + 1], static_cast<Eigen::Index>(m));
        n.se = Eigen::Map<const Eigen::VectorXd>(&state[k + 1 + m], static_cast<Eigen::Index>(m));
        nodes_.push_back(std::move(n));
    }
}

}  // namespace efdem::coarse
