#include "coarse/demixing/probability_grid.hpp"

#include "core/contracts.hpp"

namespace efdem::coarse {

ProbabilityGrid::ProbabilityGrid(int m) : m_(m) {
    EFDEM_EXPECTS(m >= 1);
}

double ProbabilityGrid::p(int i) const {
    EFDEM_EXPECTS(i >= 0 && i < m_);
    return static_cast<double>(i + 1) / static_cast<double>(m_ + 1);
}

double ProbabilityGrid::edge(int k) const {
    EFDEM_EXPECTS(k >= 0 && k <= m_ + 1);
    return static_cast<double>(k) / static_cast<double>(m_ + 1);
}

Eigen::VectorXd ProbabilityGrid::values() const {
    Eigen::VectorXd v(m_);
    for (int i = 0; i < m_; ++i) v[i] = p(i);
    return v;
}

}  // namespace efdem::coarse
