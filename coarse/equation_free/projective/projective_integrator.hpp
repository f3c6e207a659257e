#pragma once
/// \file
/// The macro integrator of coarse projective integration: one outer step = burst (healing +
/// estimation window) -> slope -> stability check -> extrapolation -> repair -> lift
/// (physics.md §10). Implementations: ProjectiveForwardEuler (fixed DT, least-squares slope),
/// PeriodProjectiveEuler (DT = k T, period-mean slope) and MultistepProjectiveIntegrator
/// (forward Euler or Adams-Bashforth 2 from the last slopes, fixed DT or error-controlled
/// adaptive DT with reject-and-redo; multistep_projective_integrator.hpp). projective_run.hpp
/// chooses one from the cpi.* keys (cpi_settings.hpp).

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/coarse_stepper.hpp"
#include "coarse/equation_free/estimators/slope_pool.hpp"
#include "coarse/equation_free/projective/multistep_state.hpp"
#include "coarse/equation_free/projective/stability_monitor.hpp"
#include "coarse/equation_free/projective/step_size_controller.hpp"
#include "coarse/equation_free/repair_report.hpp"

namespace efdem::coarse {

/// How an outer step ended. After every status the micro model is in a valid state: at the
/// end of the burst (no jump), or lifted to the projected vector.
enum class StepStatus {
    projected,              ///< burst, slope, jump and lift done (DT may have been halved)
    burst_only,             ///< DT = 0 (configured, or halved to 0): burst only, no lift
    stopped_unstable,       ///< StabilityPolicy::stop and the planned DT was flagged
    too_few_periods,        ///< DT = k T: < 2 periods after healing, even after extension
    invalid_burst,          ///< too few samples for the slope, non-finite samples, no phase
                            ///< signal, or the last sample is not at the end of the burst
    infeasible_projection,  ///< the projected vector is not finite, or the repair hook said so
    rejected,               ///< adaptive: the burst after the jump showed its error above the
                            ///< tolerance; the micro model is back where the jump started
    lift_failed,            ///< adaptive: the lift could not reach its target (overlaps left by
                            ///< moving particles did not relax); back where the jump started
};

std::string_view to_string(StepStatus status);

/// The burst every integrator runs before a jump, shared by their settings
/// (ProjectiveEulerSettings, PeriodProjectiveEulerSettings, MultistepSettings). Times in
/// sqrt(d_p/g).
struct BurstSettings {
    double healing = 10.0;  ///< start of each burst left out of the slope (>= 0)
    double window = 10.0;   ///< estimation window after healing (> 0); burst = healing + window
    /// What a DT the stability monitor flags does (fixed DT and DT = k T; the adaptive
    /// controller always shortens DT until stable, and the multistep integrator with a fixed DT
    /// does not consult the monitor).
    StabilityPolicy stability = StabilityPolicy::warn;
};

/// What the step-size controller of the multistep integrator measured and decided for one
/// jump (docs/error_control.md). Errors are RMS over the coarse vector's components [d_p for
/// the ICDF]; per-component vectors in the same unit.
struct ControllerRecord {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    bool active = false;     ///< the step was made by the multistep integrator
    bool adaptive = false;   ///< DT chosen by the controller (else fixed)
    int steps = 0;           ///< q of the jump: 1 forward Euler, 2 Adams-Bashforth 2
    double tolerance = nan;  ///< cpi.tolerance, or the jump's from cpi.accuracy (NaN when fixed)
    bool accepted = false;   ///< the jump was kept
    /// Projection noise the budget charges: the growth of the accumulated error's standard
    /// deviation (slope_pool.hpp; with the last burst's slope, DT x its standard error).
    double statistical = nan;
    /// The jump's own scatter, DT x the standard error of the slope it used (RMS); equal to
    /// `statistical` unless a pooled slope reused bursts earlier jumps used.
    double statistical_jump = nan;
    /// What the last burst's slope alone, and the whole pool (cpi.pool bursts, inverse-variance
    /// weights), would have given as the jump's own scatter at the same DT (RMS).
    double statistical_burst = nan, statistical_pool = nan;
    SlopeSource slope_source = SlopeSource::burst;  ///< cpi.slope of the jump
    int pooled_bursts = 0;                          ///< bursts the slope used (1: the last one)
    /// cpi.healing_auto: the post-lift transient statistic of the burst after the jump and its
    /// threshold (estimators/post_lift_transient.hpp); NaN when not tested.
    double transient = nan, transient_threshold = nan;
    /// cpi.window_auto: the accepted burst's V(W/2)/V(W) and its members' half-window slope
    /// correlation (estimators/window_noise.hpp; NaN when not measured), and the window of the
    /// bursts from now on.
    double window_noise_ratio = nan, window_noise_correlation = nan, window_next = nan;
    /// cpi.lift = own: RMS over the realizations and components of DT (s_r - mean s), how far
    /// the jump moved the realizations apart (NaN: they moved alike).
    double member_step = nan;
    /// cpi.accuracy (NaN otherwise): the trajectory's budget a x sigma, the ensemble's standard
    /// error sigma it was set from, the error accumulated by the jumps kept so far (after this
    /// one, when kept) and the contraction rate credited to it (trajectory_budget.hpp).
    double budget = nan, ensemble_standard_error = nan, budget_spent = nan, contraction_rate = nan;
    /// cpi.accuracy, a kept jump: the error sqrt(DT q / R) it was charged beyond its slope's
    /// variance for the ensemble's walk (trajectory_budget.hpp, walk_rate()).
    double budget_walk = nan;
    double truncation = nan;            ///< from the slope after the jump (a posteriori)
    double predicted_truncation = nan;  ///< from the slopes before it (what DT was chosen on)
    Eigen::VectorXd statistical_nodes;  ///< per component
    Eigen::VectorXd truncation_nodes;   ///< per component (noise not removed)
    /// Largest DT the tolerance allows with the realizations run, and with 2 and 4 times as
    /// many (standard errors / sqrt(2), / 2): what more realizations would buy.
    double dt_tolerance = nan, dt_tolerance_2r = nan, dt_tolerance_4r = nan;
    /// What set DT (the run file and the log hold its text: to_string(DtLimit)).
    DtLimit limited_by = DtLimit::none;
    /// The lift's own error in X (CoarseStepper::lift_error(), RMS; 0 when it reached X),
    /// judged with the other two.
    double lift = 0.0;
    double error() const { return statistical + truncation + lift; }
};

/// Everything one outer step did, for output, diagnosis and tests. Times in sqrt(d_p/g).
struct ProjectiveStepRecord {
    StepStatus status = StepStatus::invalid_burst;
    /// Empty for a plain step; otherwise warnings and reasons, "; "-separated.
    std::string message;

    double t_start = 0.0;       ///< micro clock at the start of the burst
    double burst_length = 0.0;  ///< total time run, extensions included
    double healing = 0.0;       ///< discarded start of the burst
    double window = 0.0;        ///< time span the slope was estimated over
    double dt_requested = 0.0;  ///< planned DT (k T for the period integrator)
    double dt = 0.0;            ///< DT taken; 0 when there was no jump
    /// Measured period T (NaN when the integrator does not use one).
    double period = std::numeric_limits<double>::quiet_NaN();
    int periods_per_step = 0;  ///< k taken (DT = k T); 0 for the fixed-DT integrator

    Eigen::VectorXd slope;  ///< coarse slope s [unit of X per sqrt(d_p/g)]
    /// Standard error of `slope` per component, from the spread of the members' own slopes
    /// over the same window (slope_standard_error(); same unit as slope); DT times it is the
    /// projection noise. Empty when the burst has no members or fewer than two.
    Eigen::VectorXd slope_standard_error;
    double t_end = 0.0;             ///< time of the last burst sample
    Eigen::VectorXd x_end;          ///< X(t_end), the raw last sample
    Eigen::VectorXd x_projected;    ///< X(t_end) + DT s after the repair hook (= x_end if no jump)
    RepairReport repair;            ///< what the repair hook did (default: nothing)
    StabilityAssessment stability;  ///< the monitor's verdict on the planned DT
    bool lifted = false;            ///< the stepper's lift() was called
    BurstSamples burst;             ///< the samples of this step's burst
    ControllerRecord controller;    ///< the multistep integrator's error estimates and choice

    /// The largest slope_standard_error over the components; NaN when there is none.
    double max_slope_standard_error() const {
        return slope_standard_error.size() == 0
                   ? std::numeric_limits<double>::quiet_NaN()
                   : slope_standard_error.maxCoeff<Eigen::PropagateNaN>();
    }

    /// The step ended in a state from which the next step can go on as planned (a rejected jump
    /// or a failed lift: the controller has shortened the next one, and below cpi.dt_min a burst
    /// runs directly, so the run progresses).
    bool advanced() const {
        return status == StepStatus::projected || status == StepStatus::burst_only ||
               status == StepStatus::rejected || status == StepStatus::lift_failed;
    }
};

/// The rule by which a run ends at t_end: the largest DT allowed after a burst ending at
/// `t_after_burst`, when the planned DT is `dt` and a burst lasts `burst`: the time left if it
/// is at most dt; the time left minus one burst if a full jump would leave less than a burst;
/// otherwise +infinity (also for an infinite t_end). Times compared to time_tolerance(t_end).
double end_of_run_jump_limit(double t_after_burst, double t_end, double dt, double burst);

/// The multistep integrator's other half of that rule (its jumps are always followed by a burst):
/// the length of a burst that starts at `now` (a direct one or the one after a jump) when a burst
/// lasts `burst`: `burst`, or the time left when one burst would leave less than one more, so
/// that a jump shortened below the end rule's DT (for stability) does not leave the run ending
/// short of t_end. `burst` for an infinite t_end. (The fixed forward Euler ends with a jump to
/// t_end instead, which end_of_run_jump_limit allows.)
double burst_length_to_end(double now, double t_end, double burst);

/// An integrator's own state between two steps, for a checkpoint: only the multistep
/// integrator has one (nullopt for the single-step integrators).
using IntegratorState = std::optional<MultistepState>;

/// A macro integrator: advances a CoarseStepper by one outer step.
class ProjectiveIntegrator {
  public:
    virtual ~ProjectiveIntegrator() = default;
    virtual std::string_view name() const = 0;
    /// One outer step. Never throws for a numerical condition: the record's status says what
    /// happened (check advanced()). Collective if the stepper is.
    virtual ProjectiveStepRecord step(CoarseStepper& stepper) = 0;

    /// The run ends at `t_end`: from now on a jump never carries the state past it, and the
    /// jump before the last burst leaves room for exactly that burst, so that a run whose
    /// remaining time is at least one burst ends at t_end exactly (default: no end).
    void set_end_time(double t_end) { end_time_ = t_end; }
    double end_time() const { return end_time_; }
    /// cpi.jump_until: no jump ends after `t` (default: no such time); after it every step is a
    /// burst of direct simulation. Read by the multistep integrator's controller, which
    /// CpiSettings::make_integrator chooses whenever cpi.jump_until is set, and by its
    /// cpi.accuracy budget (shared by the jumps before `t`).
    void set_jump_end(double t) { jump_end_ = t; }
    double jump_end() const { return jump_end_; }

    /// The integrator's own state between two steps (slope history, step-size controller), for
    /// a checkpoint; integrators without one save nothing (nullopt). restore_state() takes what
    /// save_state() returned, so that the next step is bit for bit the one the saved run made.
    virtual IntegratorState save_state() const { return std::nullopt; }
    /// What the integrator did over the run, in a few lines for the log and the run file
    /// (`realizations`: the ensemble's R; `bursts`: the coarse steps of the run, one burst
    /// each); empty for integrators with nothing to add.
    virtual std::string summary(int realizations, long bursts) const {
        (void)realizations;
        (void)bursts;
        return {};
    }
    /// \pre state is what this kind of integrator saves (nullopt for those without a state).
    virtual void restore_state(const IntegratorState& state);

  protected:
    /// end_of_run_jump_limit() for this integrator's end time.
    double jump_limit(double t_after_burst, double dt, double burst) const;

  private:
    double end_time_ = std::numeric_limits<double>::infinity();
    double jump_end_ = std::numeric_limits<double>::infinity();
};

}  // namespace efdem::coarse
