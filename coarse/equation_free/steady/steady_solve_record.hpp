#pragma once
/// \file
/// What every steady-state solver (newton_krylov.hpp, fixed_point_iteration.hpp) shares: the
/// stopping rule at the noise level of the ensemble, and the record of a solve (why it stopped,
/// the residual history, the cost, the best iterate).

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace efdem::coarse {

enum class SteadyStopReason {
    converged,           ///< |F| <= the fixed tolerance (a deterministic stepper)
    noise_level,         ///< |F| within noise_factor x the ensemble's noise: cannot improve further
    line_search_failed,  ///< no step length gave enough decrease of |F|
    max_iterations,      ///< the iteration limit came first
    stopped,             ///< the caller's observer asked to stop (e.g. a DEM-time budget spent)
};
std::string to_string(SteadyStopReason reason);

struct SteadySolveRecord;

/// Called after every iterate's residual is known (the record holds it as its last entry): to
/// record or report the solve as it goes. Returning a non-empty string stops the solve there
/// (SteadyStopReason::stopped, the string as the message): e.g. a budget of micro time spent.
using IterateObserver = std::function<std::string(const SteadySolveRecord&)>;

/// Stop when |F| <= max(tolerance, noise_factor * noise), noise = the norm of the standard
/// error of F from the members' spread (MapEvaluation::noise_norm). A fixed 1e-8 would never be
/// reached by an ensemble, whose F carries noise of order sigma/sqrt(R); pushing |F| below that
/// noise only fits the noise of one evaluation.
struct SteadyStopRule {
    double tolerance = 1e-10;  ///< absolute floor in |F| (what a noise-free stepper stops at)
    /// Multiple of the noise: 2 is rarely exceeded by pure noise (|e|^2/noise^2 is about
    /// chi-squared over n: P(> 4n) < 2% for n >= 2).
    double noise_factor = 2.0;

    double threshold(double noise) const;
    /// Whether r is small enough to stop; if so, `reason` says which bound it met.
    bool reached(double r, double noise, SteadyStopReason& reason) const;
};

struct SteadySolveRecord {
    SteadyStopReason reason = SteadyStopReason::max_iterations;
    std::string message;   ///< why it stopped, with the numbers
    Eigen::VectorXd x;     ///< the last iterate
    Eigen::VectorXd best;  ///< the iterate with the smallest |F| seen
    double best_residual = std::numeric_limits<double>::infinity();
    std::vector<double> residuals;  ///< |F| at each iterate, the first included
    std::vector<double> noise;      ///< the noise norm measured with each residual
    /// The same two in the stepper's coordinates X ([d_p] for the ICDF), whatever coordinates
    /// the solver works in (equal to residuals and noise when it works in X): what is recorded.
    std::vector<double> state_residuals;
    std::vector<double> state_noise;
    std::vector<int> krylov_iterations;  ///< GMRES products per Newton step (empty: fixed point)
    /// Per Newton step, the GMRES residual |G + G' d_j| before the first product and after each
    /// product j (krylov_iterations[k] + 1 values; empty: fixed point).
    std::vector<std::vector<double>> gmres_residuals;
    std::vector<double> step_lengths;  ///< line-search / damping factor per step
    /// With a fallback guess (NewtonKrylov::solve): |G| at the first guess and at the fallback,
    /// each in its own system (NaN: not evaluated, the first guess was close enough or the map
    /// noise-free), and which the solve started from.
    double first_guess_residual = std::numeric_limits<double>::quiet_NaN();
    double fallback_residual = std::numeric_limits<double>::quiet_NaN();
    bool from_fallback = false;
    int iterations = 0;     ///< steps taken
    long evaluations = 0;   ///< evaluations of the coarse map (each one burst of tau)
    double micro_time = 0;  ///< micro time of those evaluations [sqrt(d_p/g)]

    /// state_residuals at the best iterate (the one with the smallest solver |F|): what the
    /// record reports as the best |F|, in X; best_residual when nothing was recorded.
    double best_state_residual() const;

    bool converged() const {
        return reason == SteadyStopReason::converged || reason == SteadyStopReason::noise_level;
    }
    /// Adds an iterate and its residual, updating the best; `state` is the evaluation's |F| and
    /// noise in X (NaN in it: the same as residual and noise_norm).
    void add_iterate(const Eigen::VectorXd& y, double residual, double noise_norm,
                     double residual_in_state, double noise_in_state);
};

}  // namespace efdem::coarse
