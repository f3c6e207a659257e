#include "coarse/equation_free/estimators/drift_test.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "core/contracts.hpp"

namespace efdem::coarse {

DriftTest::DriftTest(std::size_t bursts, int confirmations)
    : bursts_(bursts), confirmations_(confirmations) {
    EFDEM_EXPECTS(bursts >= 2 && confirmations >= 1);
}

void DriftTest::add(const SlopeNode& node) {
    EFDEM_EXPECTS(node.slope.size() == node.se.size());
    const bool usable = node.slope.size() > 0 && node.slope.allFinite() && node.se.allFinite() &&
                        (node.se.array() >= 0).all();
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
    // One weight per burst, inverse to its mean variance; equal weights when a burst has none
    // (every member moved alike: a segregated bed in rank coordinates).
    std::vector<double> w;
    bool noiseless = false;
    for (const SlopeNode& n : nodes_) {
        const double v = n.se.array().square().mean();
        noiseless = noiseless || v == 0.0;
        w.push_back(v > 0.0 ? 1.0 / v : 0.0);
    }
    double total = 0;
    for (double& x : w) total += noiseless ? (x = 1.0) : x;
    const Eigen::Index m = nodes_.front().slope.size();
    Eigen::VectorXd s = Eigen::VectorXd::Zero(m), var = Eigen::VectorXd::Zero(m);
    for (std::size_t j = 0; j < nodes_.size(); ++j) {
        const double wj = w[j] / total;
        s += wj * nodes_[j].slope;
        var += (wj * wj) * nodes_[j].se.array().square().matrix();
    }
    // A component whose members all moved alike in every pooled burst has no noise: it is quiet
    // when it did not move (left out; round-off leaves ~1e-26), and a drift known exactly when
    // it did.
    double sum = 0;
    long counted = 0;
    for (Eigen::Index i = 0; i < m; ++i) {
        if (var[i] > 0.0) {
            sum += s[i] * s[i] / var[i];
            ++counted;
        } else if (std::abs(s[i]) > kExactlyQuiet) {
            return std::numeric_limits<double>::infinity();
        }
    }
    return counted > 0 ? std::sqrt(sum / static_cast<double>(counted)) : 0.0;
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
