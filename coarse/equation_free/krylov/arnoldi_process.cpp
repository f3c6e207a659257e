#include "coarse/equation_free/krylov/arnoldi_process.hpp"

#include <cmath>
#include <utility>

#include "core/contracts.hpp"

namespace efdem::coarse {

ArnoldiProcess::ArnoldiProcess(LinearOperator a, const Eigen::VectorXd& start, int max_steps)
    : a_(std::move(a)),
      v_(Eigen::MatrixXd::Zero(start.size(), max_steps + 1)),
      h_(Eigen::MatrixXd::Zero(max_steps + 1, max_steps)),
      beta_(start.norm()) {
    EFDEM_EXPECTS(max_steps >= 1 && beta_ > 0.0 && std::isfinite(beta_));
    v_.col(0) = start / beta_;
}

bool ArnoldiProcess::extend() {
    if (invariant_ || k_ >= h_.cols()) return false;
    Eigen::VectorXd w = a_(v_.col(k_));
    EFDEM_ASSERT(w.size() == v_.rows());
    const double product_norm = w.norm();
    for (int pass = 0; pass < 2; ++pass)
        for (int j = 0; j <= k_; ++j) {
            const double c = v_.col(j).dot(w);
            h_(j, k_) += c;
            w -= c * v_.col(j);
        }
    const double coupling = w.norm();
    ++k_;
    // A space of dimension n is the whole space, invariant whatever the coupling says.
    if (coupling <= 1e-12 * product_norm || k_ == v_.rows()) {
        invariant_ = true;
        return true;
    }
    h_(k_, k_ - 1) = coupling;
    v_.col(k_) = w / coupling;
    return true;
}

Eigen::MatrixXd ArnoldiProcess::basis() const {
    return v_.leftCols(invariant_ ? k_ : k_ + 1);
}

Eigen::MatrixXd ArnoldiProcess::hessenberg() const {
    return h_.topLeftCorner(invariant_ ? k_ : k_ + 1, k_);
}

}  // namespace efdem::coarse
