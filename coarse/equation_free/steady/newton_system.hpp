#pragma once
/// \file
/// A nonlinear system G(y) = 0 as the Newton-Krylov loop (newton_krylov.hpp) sees it: residuals
/// and directional derivatives from one kept micro state at a time (common random numbers).
/// FixedPointSystem is G = F = Phi_tau - X; ArclengthSystem (continuation) appends the
/// pseudo-arclength row.

#include <limits>

#include <Eigen/Core>

namespace efdem::coarse {

struct SystemEvaluation {
    Eigen::VectorXd g;      ///< G(y)
    double noise_norm = 0;  ///< norm of G's standard error from the ensemble (0: none)
    /// |F| and its noise norm in the stepper's coordinates (MapEvaluation::state_residual_norm,
    /// state_noise_norm), for the record; NaN: the same as |g| and noise_norm.
    double state_residual = std::numeric_limits<double>::quiet_NaN();
    double state_noise = std::numeric_limits<double>::quiet_NaN();
};

class NewtonSystem {
  public:
    virtual ~NewtonSystem() = default;
    virtual Eigen::Index dimension() const = 0;
    /// G at y from the current micro state, which is kept for what follows. \pre no base.
    virtual SystemEvaluation begin(const Eigen::VectorXd& y) = 0;
    /// G'(y) v at the base, from the kept micro state.
    virtual Eigen::VectorXd jacobian_times(const Eigen::VectorXd& v) = 0;
    /// G at another point from the kept micro state (a line-search trial).
    virtual SystemEvaluation trial(const Eigen::VectorXd& y) = 0;
    /// Forgets the kept state; the micro model continues from the last evaluation.
    virtual void end() = 0;
    /// Cost so far: map evaluations and their micro time [sqrt(d_p/g)].
    virtual long evaluations() const = 0;
    virtual double micro_time() const = 0;
};

}  // namespace efdem::coarse
