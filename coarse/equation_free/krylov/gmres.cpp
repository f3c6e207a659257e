#include "coarse/equation_free/krylov/gmres.hpp"

#include <algorithm>

#include <Eigen/QR>

#include "core/contracts.hpp"

namespace efdem::coarse {

GmresResult gmres(const LinearOperator& a, const Eigen::VectorXd& b,
                  const GmresSettings& settings) {
    EFDEM_EXPECTS(settings.max_iterations >= 1 && b.allFinite());
    GmresResult out;
    out.x = Eigen::VectorXd::Zero(b.size());
    const double beta = b.norm();
    out.residuals.push_back(beta);
    const double target = std::max(settings.relative_tolerance * beta, settings.absolute_tolerance);
    if (beta <= target || beta == 0.0) {
        out.converged = true;
        return out;
    }
    ArnoldiProcess arnoldi(a, b,
                           std::min<int>(settings.max_iterations, static_cast<int>(b.size())));
    Eigen::VectorXd y;
    while (arnoldi.extend()) {
        const Eigen::MatrixXd h = arnoldi.hessenberg();
        Eigen::VectorXd rhs = Eigen::VectorXd::Zero(h.rows());
        rhs[0] = beta;
        // (k+1) x k with k <= 30: a fresh QR per iteration costs nothing next to one product.
        y = h.colPivHouseholderQr().solve(rhs);
        out.residuals.push_back((rhs - h * y).norm());
        out.iterations = arnoldi.steps();
        if (out.residuals.back() <= target || arnoldi.invariant()) {
            out.converged = true;
            break;
        }
    }
    out.x = arnoldi.basis().leftCols(arnoldi.steps()) * y;
    return out;
}

}  // namespace efdem::coarse
