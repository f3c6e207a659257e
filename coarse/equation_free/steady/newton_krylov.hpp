#pragma once
/// \file
/// Matrix-free Newton-GMRES with a backtracking line search on |G| (docs/steady_states.md):
///
///   at y_k: G_k = G(y_k) from a fresh micro state (kept: common random numbers);
///   GMRES:  G'(y_k) d = -G_k, products by CRN differences, to |G_k + G' d| <=
///           max(forcing |G_k|, half the stopping threshold);
///   search: y_k + s d for s = 1, 1/2, ... from the same kept state, accepted at
///           |G(y_k + s d)| <= (1 - 1e-4 s) |G_k| (Armijo on |G|);
///   the micro model continues from the accepted trial, where y_{k+1} is evaluated afresh.
///
/// Stops at the noise level of the ensemble (SteadyStopRule), the iteration limit, or when the
/// line search finds no decrease. Cost per Newton step: (1 + GMRES products + trials) bursts.

#include "coarse/equation_free/krylov/gmres.hpp"
#include "coarse/equation_free/steady/newton_system.hpp"
#include "coarse/equation_free/steady/steady_solve_record.hpp"

namespace efdem::coarse {

struct NewtonKrylovSettings {
    SteadyStopRule stop;
    int max_iterations = 20;  ///< Newton steps
    /// Most GMRES products per Newton step (at most the dimension is ever used).
    int max_krylov = 30;
    /// Relative GMRES tolerance (the forcing term): an inexact Newton step.
    double forcing = 1e-3;
    int max_backtracks = 6;  ///< halvings of the step before the line search gives up
    /// Called at every iterate (may be empty); a non-empty answer stops the solve.
    IterateObserver observer;
};

/// A second first guess for NewtonKrylov::solve, evaluated only when the first guess is noisy and
/// far: |G| there above `ratio` x the stopping threshold, with a noise norm > 0. It may come
/// with its own system (e.g. a different constraint row), in which the solve then goes on; it
/// must work on the same micro model (the same evaluation counters). The solve starts from
/// whichever guess has the smaller |G| in its own system; when that is the first guess, it is
/// evaluated afresh (the kept micro state is the fallback's): one or two extra bursts. In
/// continuation the first guess is the predictor, whose tangent carries the noise of the points
/// it came from, and the fallback is the last point at the predicted parameter, held there.
struct FallbackGuess {
    Eigen::VectorXd y;
    double ratio = 2.0;
    NewtonSystem* system = nullptr;  ///< nullptr: the solve's own system
};

class NewtonKrylov {
  public:
    explicit NewtonKrylov(const NewtonKrylovSettings& settings);
    /// Solves G(y) = 0 from y0. Leaves no base on `system`. Never throws for a numerical
    /// condition: the record says why it stopped.
    SteadySolveRecord solve(NewtonSystem& first_system, const Eigen::VectorXd& y0,
                            const FallbackGuess* fallback = nullptr) const;
    const NewtonKrylovSettings& settings() const { return settings_; }

  private:
    /// The first iterate's evaluation: of y in *system (evaluated as e) or, if closer to steady,
    /// of the fallback (then y and system become its); records both residuals in rec.
    SystemEvaluation choose_start(NewtonSystem*& system, Eigen::VectorXd& y, SystemEvaluation e,
                                  const FallbackGuess& fallback, SteadySolveRecord& rec) const;

    NewtonKrylovSettings settings_;
};

}  // namespace efdem::coarse
