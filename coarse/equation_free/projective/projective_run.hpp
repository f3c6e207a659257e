#pragma once
/// \file
/// ProjectiveRun: the coarse run loop of coarse projective integration. It owns the numerical
/// policy of a whole run, on any CoarseStepper (an MPI ensemble of DEM realizations or a toy
/// ODE alike):
///
/// * warm-up: `warmup` of direct simulation before the first coarse step (a new run only), or,
///   with warmup_until_steady, on until the phase signal (the bed's centre of mass) no longer
///   drifts beyond its noise (phase_drift.hpp) — the fast transient is judged from the run; in
///   pieces with safe points between them (ProjectiveRunState::warmup_done, warmup_tail);
/// * the step loop: one ProjectiveIntegrator::step after another until the end time;
/// * the end-of-run rule: the integrators shorten their last jumps so that the run ends at
///   t_end exactly; a rest shorter than one burst ends the run early, with a log line;
/// * stop conditions: StepStatus::stopped_unstable, or kMaxStepsWithoutProgress consecutive
///   steps without a jump (the run would silently have become a direct run);
/// * cpi.finish = steady: the run ends after the coarse step whose last sample finds the stepper
///   at an end state (every realization at rest), with the time it was reached;
/// * observable fallback: when a step is rejected as invalid_burst and a fallback coarse
///   variable exists (e.g. the compact (A,B,C,D) fit failed; the full ICDF is always defined),
///   the stepper is switched to it and the run continues on it for good;
/// * a run without a projective jump (every coarse step was a burst only: the run was shorter
///   than warm-up + one burst + anything to jump, the warm-up ran to the end, the adaptive
///   controller declined every jump, period bursts were extended to the end) is a direct run
///   in disguise: a warning, and its end status says so ("completed (no projective jump: ...)").
///   Known for a run whose every coarse step this call saw (a new run, or one resumed before
///   its first coarse step): the loop state does not count earlier jumps.
///
/// What happens around the steps (recording, progress, checkpoints) is done by observers that
/// the caller plugs in (ProjectiveRunObserver). The loop's own state (ProjectiveRunState) is
/// what a checkpoint saves; run() continues from it on a restart.
///
/// \code
/// coarse::ProjectiveRun run(settings, stepper, {.name = "icdf", .repair = clip});
/// run.add_observer(recorder);                       // step_done(): write the step record
/// const coarse::ProjectiveRunOutcome out = run.run(t_end - stepper.time());
/// if (out.end_status != "completed") log::warn("{}", out.end_status);
/// \endcode

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coarse/equation_free/coarse_stepper.hpp"
#include "coarse/equation_free/estimators/drift_test.hpp"
#include "coarse/equation_free/projective/cpi_settings.hpp"
#include "coarse/equation_free/projective/projective_integrator.hpp"

namespace efdem::coarse {

/// Consecutive outer steps without a jump after which a run stops.
inline constexpr int kMaxStepsWithoutProgress = 3;

/// The loop's state between two coarse steps: all a restart needs besides the stepper's.
struct ProjectiveRunState {
    double t_origin = std::numeric_limits<double>::quiet_NaN();  ///< time the run started at
    long coarse_steps = 0;                                       ///< outer steps done
    long without_progress = 0;  ///< consecutive steps without a jump
    bool fell_back = false;     ///< the primary coarse variable failed; the fallback is in use
    /// The warm-up is done (false in a state saved before or during it: a run resumed from
    /// there does the rest of the warm-up).
    bool warmed_up = false;
    /// Warm-up time simulated so far. The warm-up runs in pieces (of one burst length; with
    /// warmup_until = steady, then of one window while it drifts), with a safe point before
    /// each piece but the first, where a run can be checkpointed and stopped; a run resumed
    /// there runs only the rest.
    double warmup_done = 0;
    /// warmup_until = steady, at a safe point inside the warm-up: the samples of the last burst
    /// length (times and the members' phase and expansion signals; the other fields empty),
    /// which its next drift test reads, so that a resumed run judges the drift exactly as the
    /// uninterrupted one. Empty everywhere else.
    BurstSamples warmup_tail;
    /// The integrator's own state (ProjectiveIntegrator::save_state(); nullopt for the
    /// single-step integrators).
    IntegratorState integrator;
    /// cpi.finish = steady: the drift test's pool of the last bursts' slopes (DriftTest::save();
    /// empty when the pool is or the key is off).
    std::vector<double> drift;
};

/// A coarse variable the loop can integrate: how projected vectors are repaired, how the
/// stepper is made to restrict to it, and why its restriction failed.
struct CoarseVariable {
    std::string name;         ///< short name, e.g. "icdf" (used in the end status)
    std::string description;  ///< for messages, e.g. "full ICDF"
    RepairHook repair;        ///< applied to every projected vector before lifting (may be empty)
    /// Switches the stepper's restriction to this variable (may be empty: nothing to switch).
    std::function<void()> select;
    /// Why the most recent failed restriction failed (may be empty).
    std::function<std::string()> failure;
};

class ProjectiveRun;

/// Called by ProjectiveRun around its steps, in the order the observers were added. Every
/// callback runs on the rank that drives the loop.
class ProjectiveRunObserver {
  public:
    virtual ~ProjectiveRunObserver() = default;
    /// After the warm-up of a new run (not called on a resumed run or without warm-up).
    virtual void warmup_done(const ProjectiveRun& run) { (void)run; }
    /// Before every coarse step, where nothing of a burst is pending: checkpoints go here. Also
    /// called before the warm-up and between its pieces (state().warmed_up false), where a run
    /// that must stop can go back to.
    virtual void between_steps(const ProjectiveRun& run) { (void)run; }
    /// After every coarse step (run.state().coarse_steps already counts it).
    virtual void step_done(const ProjectiveRun& run, const ProjectiveStepRecord& record) {
        (void)run;
        (void)record;
    }
};

/// How a run ended.
struct ProjectiveRunOutcome {
    /// "completed", "completed (<primary> observable fell back to <fallback>)",
    /// "completed (no projective jump: ...)", or "stopped at t = ...: <status> (<message>)".
    std::string end_status;
    long coarse_steps = 0;
    long jumps = 0;             ///< projective jumps (DT > 0, accepted) made by this call of run()
    double simulated_time = 0;  ///< stepper time at the end minus t_origin
    bool fell_back = false;
    /// cpi.finish = steady: when the end state was reached (CoarseStepper::end_state_since, or
    /// for a moving ensemble DriftTest::since());
    /// NaN when the run ended otherwise.
    double end_state_time = std::numeric_limits<double>::quiet_NaN();
};

class ProjectiveRun {
  public:
    /// `stepper` is already restricting to `primary`. `fallback`: the variable to switch to
    /// when `primary` fails (none: such a failure counts as a step without progress).
    ProjectiveRun(const CpiSettings& settings, CoarseStepper& stepper, CoarseVariable primary,
                  std::optional<CoarseVariable> fallback = std::nullopt);

    /// Observers are not owned and must outlive run().
    void add_observer(ProjectiveRunObserver& observer) { observers_.push_back(&observer); }

    /// Runs until t_origin + duration. A new run (no `resume`) starts at the stepper's time
    /// with the warm-up; a resumed one continues from the saved loop state (the stepper must
    /// be restored to the same point). Never throws for a numerical condition.
    ProjectiveRunOutcome run(double duration,
                             const std::optional<ProjectiveRunState>& resume = std::nullopt);

    const ProjectiveRunState& state() const { return state_; }
    /// The integrator in use (after run() started).
    const ProjectiveIntegrator& integrator() const { return *integrator_; }
    const CpiSettings& settings() const { return settings_; }
    const CoarseStepper& stepper() const { return stepper_; }
    double end_time() const { return t_end_; }
    /// Micro time the run still needs from the stepper's time when the next jumps are `dt`.
    double planned_micro_time(double dt) const;

  private:
    void use(const CoarseVariable& variable);
    /// cpi.warmup of direct simulation; with warmup_until_steady on in windows until the phase
    /// signal no longer drifts (at most warmup_max longer; always leaving one burst of the run).
    void warm_up();
    /// A safe point inside a warm-up until steady: the observers see the state with the
    /// samples the next drift test reads (`w`'s last burst length) in warmup_tail.
    void warmup_safe_point(const BurstSamples& w, double burst);
    /// cpi.finish = steady: feeds the drift test from a step's record; true when the moving
    /// ensemble is statistically steady (DriftTest::steady()).
    bool steady_by_drift(const ProjectiveStepRecord& rec);

    /// cpi.finish = steady for a moving ensemble: the slopes of the last 4 accepted bursts pooled,
    /// steady at 2 quiet checks in a row (docs/error_control.md §1).
    static constexpr std::size_t kDriftBursts = 4;
    static constexpr int kDriftConfirmations = 2;

    CpiSettings settings_;
    CoarseStepper& stepper_;
    CoarseVariable primary_;
    std::optional<CoarseVariable> fallback_;
    std::unique_ptr<ProjectiveIntegrator> integrator_;
    std::vector<ProjectiveRunObserver*> observers_;
    ProjectiveRunState state_;
    DriftTest drift_{kDriftBursts, kDriftConfirmations};
    double t_end_ = std::numeric_limits<double>::infinity();
};

/// Micro time a run needs from t_now to t_end with bursts of `burst` (> 0) and jumps of `dt`,
/// shortened at the end by the integrators' rule (end_of_run_jump_limit).
double planned_micro_time(double t_now, double t_end, double burst, double dt);

}  // namespace efdem::coarse
