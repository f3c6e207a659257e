#pragma once
/// \file
/// The run loop of mode = steady and mode = continuation (docs/steady_states.md), on any
/// CoarseStepper, as ProjectiveRun is for CPI:
///
///   warm-up:  run steady.warmup directly; the last sample X0 is the initial guess (the
///             packed start is not on the slow manifold);
///   steady:   Newton-GMRES (CRN derivatives) or Anderson on F(X) = Phi_tau(X) - X from X0,
///             then the leading eigenvalues of dPhi_tau/dX at the answer (Newton only);
///   continuation: pseudo-arclength in lambda = parameter / scale from (X0, start) towards
///             the end of the range, the leading eigenvalue at every point.
///
/// Every lifted point goes through the coarse variable's repair (an ICDF stays monotone and
/// inside the heights the particles occupy), and every parameter value through the hook that
/// sets it on the micro model. Observers see each iterate (to record and report it, and to
/// stop on a budget) and each branch point.

#include <functional>
#include <limits>
#include <string>

#include <Eigen/Core>

#include "coarse/equation_free/steady/coarse_map.hpp"
#include "coarse/equation_free/steady/coarse_spectrum.hpp"
#include "coarse/equation_free/steady/continuation.hpp"
#include "coarse/equation_free/steady/steady_run_settings.hpp"
#include "coarse/equation_free/steady/steady_solve_record.hpp"

namespace efdem::coarse {

/// What a steady or continuation run found.
struct SteadyRunOutcome {
    bool continuation = false;
    std::string solver;                   ///< "newton" or "anderson"
    std::string coordinates = "heights";  ///< what the solver worked in (CoarseCoordinates::name)
    double tau = 0;                       ///< micro time of one evaluation
    /// h of the CRN differences, in the solver's coordinates, and where it came from (the scene
    /// key, or the noise measured at the end of the warm-up).
    double difference_step = 0;
    std::string difference_step_origin;
    double warmup_end = 0;  ///< micro clock at the end of the warm-up
    /// A cpi run that handed its state to the solve (cpi.hand_off = steady): the coarse time at
    /// which it ended, the time the process took to reach the end state the solve then refined
    /// (NaN: mode = steady | continuation, which start from a warm-up).
    double hand_off_time = std::numeric_limits<double>::quiet_NaN();
    /// A hand-off: when the cpi run's kept bursts reached the answer and stayed within the
    /// solve's threshold of it (coarse::arrival_time; NaN: not reached, or not a hand-off).
    double end_state_time = std::numeric_limits<double>::quiet_NaN();
    /// The run resumed a checkpoint and every burst it saw was within the radius: the end state
    /// may have been reached before, so end_state_time is an upper bound.
    bool end_state_time_is_bound = false;
    Eigen::VectorXd x0;  ///< the initial guess (last warm-up sample)
    /// mode = steady: the solve, and the spectrum at its answer (empty: not computed).
    SteadySolveRecord solve;
    CoarseSpectrum spectrum;
    /// mode = continuation: the branch, with parameters in the scene's units (not scaled).
    Branch branch;
    std::string parameter;
    double parameter_scale = 1;
    long repairs = 0;           ///< evaluations whose lifted point the repair changed
    double largest_repair = 0;  ///< the largest change it made
    long evaluations = 0;       ///< of Phi_tau, each tau of micro time per member
    double micro_time = 0;      ///< spent after the warm-up (evaluations x tau)
    bool converged = false;     ///< steady: the solve stopped at its rule; continuation: >= 1 point
    std::string end_status;     ///< "completed: ..." or "not converged: ..." (the run file's)
};

class SteadyRun {
  public:
    /// `repair` (may be empty): makes a lifted point liftable; `set_parameter` (continuation:
    /// required): sets the parameter (scene units) on the micro model.
    /// `coordinates` (may be empty: the coarse vector itself): what the solver works in; every
    /// vector this run reports (outcome, observers) is the coarse vector X again.
    SteadyRun(const SteadyRunSettings& settings, CoarseStepper& stepper, RepairHook repair,
              std::function<void(double)> set_parameter = {}, CoarseCoordinates coordinates = {});
    /// Called at every iterate of every solve (steady: one solve; continuation: the first point
    /// and each corrector); a non-empty answer stops the run there.
    void set_iterate_observer(IterateObserver observer) { iterate_observer_ = std::move(observer); }
    /// Called with the branch (scene units) after each new point.
    void set_point_observer(BranchObserver observer) { point_observer_ = std::move(observer); }

    /// Warm-up, then the solve or the continuation.
    SteadyRunOutcome run();
    /// What the settings alone say of the outcome (mode, solver, coordinates, tau, parameter):
    /// where run() starts, and what a caller reports of a run cut short.
    SteadyRunOutcome header() const;

  private:
    /// h for the CRN differences after the warm-up `warm`: steady.difference_step, or
    /// difference_noise_multiple x the noise norm of its last sample's members in the solver's
    /// coordinates (the scene's fallback without two members), at most a curvature cap (1 in
    /// log gaps, a quarter of |X| in heights). Kept for header().
    double difference_step(const BurstSamples& warm);
    void solve_steady(CoarseMap& map, SteadyRunOutcome& out);
    void continue_branch(CoarseMap& map, SteadyRunOutcome& out);
    Branch unscaled(const Branch& branch) const;
    /// u -> X of the first `n` components (the rest, e.g. a continuation parameter, kept).
    Eigen::VectorXd state(const Eigen::VectorXd& y, Eigen::Index n) const;
    Eigen::VectorXd solver_point(const Eigen::VectorXd& x) const;
    IterateObserver observer_in_states(Eigen::Index n) const;
    CoarseCoordinates coordinates_;

    SteadyRunSettings settings_;
    CoarseStepper& stepper_;
    RepairHook repair_;
    std::function<void(double)> set_parameter_;
    IterateObserver iterate_observer_;
    BranchObserver point_observer_;
    double difference_step_ = 0;  ///< once the warm-up is done (0 before)
    std::string difference_step_origin_;
};

/// Segregation measure of a coarse ICDF: the mean of its nodes, an estimate of the observed
/// species' mean height [d_p]; and an upper bound on its standard error from the noise norm
/// |SE| of the coarse vector: SE(mean_i X_i) <= mean_i SE_i <= |SE|_2 / sqrt(n) (the standard
/// deviation of a sum is at most the sum of the standard deviations; then Cauchy-Schwarz).
double mean_height(const Eigen::VectorXd& x);
double mean_height_error_bound(double noise_norm, Eigen::Index n);

}  // namespace efdem::coarse
