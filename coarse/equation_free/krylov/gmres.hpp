#pragma once
/// \file
/// GMRES without restarts on a matrix-free operator (Saad & Schultz 1986), built on
/// ArnoldiProcess: x_k = V_k y_k with y_k = argmin |beta e_1 - H_k y|. Our own rather than
/// Eigen's unsupported GMRES because every product is a burst of micro simulation: the caller
/// needs the residual after every iteration (the run log and the result record list them; Eigen
/// reports only the last), a stop at an absolute floor set by the ensemble noise besides the
/// relative forcing term, and no restart (a restart throws away products that cost bursts).
/// x_0 = 0, so the first residual is |b|.

#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/krylov/arnoldi_process.hpp"

namespace efdem::coarse {

struct GmresSettings {
    /// Most products (Krylov dimension), >= 1.
    int max_iterations = 30;
    /// Stop when |b - A x| <= max(relative_tolerance |b|, absolute_tolerance).
    double relative_tolerance = 1e-3;
    double absolute_tolerance = 0.0;
};

struct GmresResult {
    Eigen::VectorXd x;
    int iterations = 0;  ///< products with A
    /// |b - A x_k| for k = 0 ... iterations, from the least-squares problem (exact in exact
    /// arithmetic with exact products; with noisy products it is the residual of the model).
    std::vector<double> residuals;
    bool converged = false;  ///< the tolerance was met (or the space became invariant)
};

/// \pre b finite; settings.max_iterations >= 1. A zero b gives x = 0 without a product.
GmresResult gmres(const LinearOperator& a, const Eigen::VectorXd& b, const GmresSettings& settings);

}  // namespace efdem::coarse
