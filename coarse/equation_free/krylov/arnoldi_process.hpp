#pragma once
/// \file
/// The Arnoldi process on a matrix-free operator: an orthonormal basis V_k of the Krylov space
/// K_k(A, v_0) and the (k+1) x k upper Hessenberg H_k with A V_k = V_{k+1} H_k. The one Krylov
/// engine behind the GMRES of the Newton steps (gmres.hpp) and the coarse eigenvalues
/// (coarse_spectrum.hpp), so that both see every product the same way. Each product is a call
/// of the operator (for the coarse map: a burst of tau), so the process is built one step at a
/// time and the caller decides when to stop.

#include <functional>

#include <Eigen/Core>

namespace efdem::coarse {

/// y = A x for a matrix-free A (e.g. a directional derivative of the coarse map).
using LinearOperator = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

class ArnoldiProcess {
  public:
    /// \pre start is finite and nonzero, max_steps >= 1.
    ArnoldiProcess(LinearOperator a, const Eigen::VectorXd& start, int max_steps);

    /// One more step (one product with A), orthogonalized twice by modified Gram-Schmidt
    /// ("twice is enough": orthogonal to round-off even when the product lies nearly in the
    /// space). Returns false, without a product, when the space is already invariant or
    /// max_steps are done. The space becomes invariant when the new direction's norm is below
    /// 1e-12 of the product's: A V_k = V_k H_k then holds to round-off.
    bool extend();

    int steps() const { return k_; }
    bool invariant() const { return invariant_; }
    double start_norm() const { return beta_; }
    /// v_0 ... v_k (n x (k+1); n x k when invariant).
    Eigen::MatrixXd basis() const;
    /// H_k: (k+1) x k (k x k when invariant).
    Eigen::MatrixXd hessenberg() const;
    /// The square part of H_k (k x k): V_k^T A V_k.
    Eigen::MatrixXd square_hessenberg() const { return h_.topLeftCorner(k_, k_); }
    /// h_{k+1,k}: the size of what A V_k leaves outside the space (0 when invariant).
    double next_coupling() const { return k_ == 0 || invariant_ ? 0.0 : h_(k_, k_ - 1); }

  private:
    LinearOperator a_;
    Eigen::MatrixXd v_;  ///< n x (max_steps + 1)
    Eigen::MatrixXd h_;  ///< (max_steps + 1) x max_steps
    double beta_;
    int k_ = 0;
    bool invariant_ = false;
};

}  // namespace efdem::coarse
