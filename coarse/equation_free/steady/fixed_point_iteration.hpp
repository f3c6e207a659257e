#pragma once
/// \file
/// The cheap robust alternative to Newton-Krylov: damped or Anderson-accelerated fixed-point
/// iteration on Phi_tau (Walker & Ni 2011), one map evaluation per iteration, no derivatives,
/// no kept micro state (any CoarseStepper will do):
///
///   f_k = Phi(x_k) - x_k;
///   depth 0 (damped):  x_{k+1} = x_k + beta f_k;
///   depth m (Anderson): gamma = argmin |f_k - dF gamma| over the last m differences
///       dF = [f_{j+1} - f_j], dX = [x_{j+1} - x_j];  x_{k+1} = x_k + beta f_k - (dX + beta dF)
///       gamma.
///
/// The history is dropped when |f| grows past the best seen (the extrapolation went wrong, or
/// noise dominates the differences). Same stopping rule and record as NewtonKrylov. Plain
/// damped iteration converges when every coarse eigenvalue satisfies |1 - beta (1 - mu)| < 1,
/// i.e. for a stable steady state (|mu| < 1, beta <= 1) at the rate of the slowest mode, which
/// is the direct simulation's rate: Anderson is what makes it competitive.

#include "coarse/equation_free/steady/coarse_map.hpp"
#include "coarse/equation_free/steady/steady_solve_record.hpp"

namespace efdem::coarse {

struct FixedPointSettings {
    SteadyStopRule stop;
    int max_iterations = 100;
    double damping = 1.0;  ///< beta in (0, 1]
    int depth = 3;         ///< Anderson depth m (0: damped iteration)
    /// Called at every iterate (may be empty); a non-empty answer stops the solve.
    IterateObserver observer;
};

class FixedPointIteration {
  public:
    explicit FixedPointIteration(const FixedPointSettings& settings);
    /// Iterates on `map` (no base on it) from x0 at `parameter`.
    SteadySolveRecord solve(CoarseMap& map, const Eigen::VectorXd& x0,
                            double parameter = 0.0) const;

  private:
    FixedPointSettings settings_;
};

}  // namespace efdem::coarse
