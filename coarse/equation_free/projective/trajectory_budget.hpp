#pragma once
/// \file
/// TrajectoryBudget (cpi.accuracy = a): the accuracy of the whole trajectory, stated as a
/// multiple a of the ensemble's own standard error, turned into the tolerance of each jump
/// (docs/error_control.md §10).
///
/// The ensemble's standard error sigma is the RMS over the coarse vector's components of
/// sqrt(var_members / R) — what the ensemble mean of R realizations is uncertain by anyway. The
/// error CPI adds to the trajectory may be at most B = a sigma at every time. What the jumps
/// made so far have added is accumulated: their statistical parts as variances (a pooled
/// slope's correlation with earlier jumps is already in the charged part, statistical_error()),
/// their truncation parts linearly, both contracted by exp(-lambda t) over the time since they
/// were made, lambda the decay rate of the slow dynamics that two accepted bursts in a row
/// resolved (credit(); none: no credit). Contraction is credited to errors already made,
/// over time already run — never to the future. The next jump's DT is the largest for which
/// jumps like it, repeated over the rest of the run (H to its end, one every DT + burst), keep
/// the accumulated error within B:
///   T d + n tau(DT) + sqrt(V d^2 + n s(DT)^2) <= B,   n = H / (DT + burst),
/// d = exp(-lambda (t0 - t_last)), and its tolerance is that jump's error s(DT) + tau(DT). Where
/// the slope's noise is the ensemble's walk (at U_s = 0.19: bench/walk_budget.py) a jump adds
/// more than its slope's variance s(DT)^2: the slope's error is correlated with the walk already
/// in the state it extrapolates from (twice DT q / R) and the jump stands in for the walk of DT a
/// direct ensemble makes (less DT q / R), so each jump is charged s(DT)^2 + DT q / R, q / R the
/// mean's walk per unit time (walk_rate()). Once
/// the budget is spent the tolerance falls below what cpi.dt_min allows and the run goes on
/// directly.
///
/// \code
/// TrajectoryBudget b(1.0);
/// // From a burst whose members no lift gathered onto one coarse vector:
/// b.measure(TrajectoryBudget::standard_error(burst, t_window));
/// b.credit(lambda, 1.0 / burst_length);  // every accepted burst: its resolved decay, or NaN
/// const double tol = b.jump_tolerance(model, end_time, burst_length, dt_max);
/// // ... jump, judge against tol, and when kept:
/// b.commit(t_landed, statistical, truncation, dt * walk_rate(last_burst, window, fit));
/// \endcode

#include <limits>

#include <Eigen/Core>

#include "coarse/equation_free/coarse_stepper.hpp"
#include "coarse/equation_free/estimators/slope_estimators.hpp"
#include "coarse/equation_free/projective/step_size_controller.hpp"

namespace efdem::coarse {

/// What a TrajectoryBudget remembers between jumps (saved in a checkpoint).
struct TrajectoryBudgetState {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    double variance = 0.0;    ///< accumulated statistical error squared at t_last [unit^2]
    double truncation = 0.0;  ///< accumulated truncation error at t_last [unit]
    double t_last = nan;      ///< when they were last updated (NaN: no jump yet)
    double sigma = nan;       ///< the ensemble's standard error last measured (NaN: none yet)
    /// The decay rate the last accepted burst resolved (>= 0; NaN: none), and the rate credited
    /// now (0: none), see credit().
    double last_rate = nan;
    double rate = 0.0;
};

/// The ensemble mean's walk per unit time, q / R, from a burst's slope over `window` fitted as
/// FIT says: the least-squares slope of a walk over W has variance 1.2 q / (W R), the increment
/// q / (W R) (walk_slope_variance_factor()), so q / R = W se^2 / factor (mean over the
/// components). The charge it makes, DT q / R per jump, is the same for both: either slope's
/// covariance with the walk already in the state is q / R. 0 for a window <= 0 or no components.
double walk_rate(const SlopeNode& burst, double window, SlopeFit fit);

class TrajectoryBudget {
  public:
    /// \pre accuracy > 0 finite.
    explicit TrajectoryBudget(double accuracy);

    /// The ensemble's standard error of members (R x dim, R >= 2): RMS over the components of
    /// sqrt(unbiased variance / R) (ensemble_standard_error()). NaN when R < 2.
    static double standard_error(const Eigen::MatrixXd& members);
    /// The same over a burst's samples from t_from on: the RMS of the samples' standard errors
    /// (NaN when the burst carries no members, or none of R >= 2, from t_from on).
    static double standard_error(const BurstSamples& burst, double t_from);

    /// Takes sigma (finite, >= 0) as the ensemble's standard error from now on.
    void measure(double sigma);
    bool ready() const;  ///< a sigma has been measured
    double accuracy() const { return accuracy_; }
    /// B = a sigma (NaN before a measurement).
    double budget() const;
    /// The accumulated error at time t (>= t_last), contracted at rate() since t_last:
    /// (T + sqrt(V)) e^(-rate dt).
    double spent(double t) const;

    /**
     * \brief An accepted burst resolved a decay of its slope at `measured` (> 0, 1/time) or
     *        none (NaN). The rate credited from now on is the smaller of this and the previous
     *        burst's when both resolved one, at most `cap` (faster is a fast transient, not the
     *        slow dynamics); else 0. A single burst's decay (a transient after a lift or after
     *        the warm-up) earns no credit.
     */
    void credit(double measured, double cap);
    double rate() const { return state_.rate; }

    /**
     * \brief The tolerance of the next jump, starting at model.t0, of a run that ends at
     *        `end_time` with bursts of `burst` after each jump and jumps of at most `dt_max`
     *        (see the file comment). 0 when the budget is spent.
     *        Each jump of DT is charged DT walk beyond its slope's variance (walk_rate(); 0:
     *        none).
     * \pre ready(), burst > 0, dt_max > 0 finite, end_time > model.t0 finite, walk >= 0.
     */
    double jump_tolerance(const JumpErrorModel& model, double end_time, double burst, double dt_max,
                          double walk = 0.0) const;

    /// A jump kept that landed at t_landed with these parts of its error and the variance
    /// `walk` (DT walk_rate(), >= 0) it added beyond its slope's; the accumulated error is first
    /// contracted at rate() from t_last to t_landed.
    void commit(double t_landed, double statistical, double truncation, double walk = 0.0);

    const TrajectoryBudgetState& state() const { return state_; }
    void restore(const TrajectoryBudgetState& state) { state_ = state; }

  private:
    double accuracy_;
    TrajectoryBudgetState state_;
};

}  // namespace efdem::coarse
