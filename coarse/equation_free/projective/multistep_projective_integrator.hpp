#pragma once
/// \file
/// MultistepProjectiveIntegrator: projective forward Euler or Adams-Bashforth 2 from the
/// slopes of the last bursts, with a fixed DT or with DT chosen by an error controller that
/// rejects and redoes a jump whose error exceeds the tolerance (docs/error_control.md).
///
/// One step, adaptive (the stepper is at the end of the last accepted burst, X_n):
///   1. StepSizeController::plan(): DT from the predicted error (statistical + truncation,
///      from the slopes measured so far) and the caps (step_size_controller.hpp); DT = 0: one
///      burst of direct simulation instead (status burst_only, the record says why);
///   2. keep the micro state, project X_n + sum_k W_k s_k, repair, lift;
///   3. run the next burst (provisional samples) and measure its slope;
///   4. StepSizeController::judge() with the curvature that slope shows: accept (samples
///      final, the slope joins the history) or reject (back to the kept state, the next step
///      tries a smaller DT; status rejected).
/// The very first step of a run runs one burst only (its slope is the first jump's). No lift
/// precedes it, so its healing is direct simulation like the window: when healing >= window,
/// adaptive runs also fit the window just before the last one, [t - 2 window, t - window), and
/// the first jump is planned from the curvature of those two slopes (a node used for the
/// curvature only, never projected from) instead of being capped at one burst.
/// With a fixed DT (adaptive = false) steps 1-4 run without keeping, judging or rejecting;
/// the error estimates are still recorded.
///
/// \code
/// MultistepSettings s;
/// s.steps = 2;                                     // Adams-Bashforth 2
/// s.control = {.tolerance = 0.05, .dt_min = 10, .dt_max = 160};
/// MultistepProjectiveIntegrator ab2(s, repair);
/// const ProjectiveStepRecord rec = ab2.step(stepper);  // stepper.can_keep_state()
/// \endcode

#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "coarse/equation_free/estimators/slope_pool.hpp"
#include "coarse/equation_free/estimators/window_noise.hpp"
#include "coarse/equation_free/projective/multistep_projection.hpp"
#include "coarse/equation_free/projective/projective_integrator.hpp"
#include "coarse/equation_free/projective/stability_monitor.hpp"
#include "coarse/equation_free/projective/step_size_controller.hpp"
#include "coarse/equation_free/projective/trajectory_budget.hpp"

namespace efdem::coarse {

/// A decision forced on one jump attempt (tests only: reject it, or halve its planned DT).
struct ForcedDecision {
    enum class Kind { none, reject, shrink } kind = Kind::none;
    long attempt = 0;  ///< 1-based jump attempt it applies to
};

struct MultistepSettings {
    /// Healing and window of every burst (burst.stability is not consulted: adaptive DT is
    /// always shortened until stable, a fixed DT is not assessed).
    BurstSettings burst;
    int steps = 1;         ///< q: 1 forward Euler, 2 Adams-Bashforth 2
    bool adaptive = true;  ///< DT by the controller; false: `dt` for every jump
    double dt = 80.0;      ///< adaptive = false: the projective step (>= 0)
    /// adaptive: the first jump is at most this; NaN: planned from the tolerance when the first
    /// burst measured a curvature (healing >= window), else one burst, but at least dt_min.
    double first_dt = std::numeric_limits<double>::quiet_NaN();
    StepSizeSettings control;
    /// adaptive: DT is rounded down to a whole multiple of this (the sampling interval, so
    /// that bursts stay on the sampling grid and the run ends at its end time; 0: no rounding).
    double dt_quantum = 0.0;
    ForcedDecision force;
    /// adaptive: a burst whose phase signal drifts faster than this (and beyond its noise) is
    /// still in a fast transient: no jump from it (phase_drift.hpp) [unit per sqrt(d_p/g)].
    /// Infinite: no check. From a scene: steady_drift_rate() (cpi_settings.hpp).
    double drift_rate = std::numeric_limits<double>::infinity();
    /// Where the jump's slope comes from (cpi.slope): the last burst's, or pooled over the last
    /// `pool` accepted bursts (fewer at the start; slope_pool.hpp; forward Euler only), its
    /// statistical error charged as the growth of the accumulated error (the pooled jumps'
    /// errors are correlated).
    SlopeSource slope = SlopeSource::burst;
    std::size_t pool = 4;  ///< cpi.pool: bursts a pooled slope uses (>= 1)
    /// cpi.slope_fit: how a burst's window becomes its slope and its members' slopes (least
    /// squares, or the window's increment: the best for a noise that is a walk,
    /// docs/error_control.md §7). Not with window_auto (its noise model is least squares').
    SlopeFit slope_fit = SlopeFit::least_squares;
    /// cpi.healing_auto: every burst that follows a lift is tested for a post-lift transient
    /// (estimators/post_lift_transient.hpp); the bursts after it heal for burst.healing when
    /// one is measured and for healing_min when none is, the window filling the rest of the
    /// burst (whose length, burst.healing + burst.window, never changes).
    bool healing_auto = false;
    double healing_min = 0.0;  ///< the shortest healing (0 <= healing_min <= burst.healing)
    /// cpi.window_auto (adaptive): every accepted burst measures how its slope's noise falls
    /// with the window (estimators/window_noise.hpp); the bursts after it use the shortest
    /// window within window_inefficiency_limit of the best efficiency for the healing they
    /// have, on the dt_quantum grid from window_min to window_max; when the ensemble mean's
    /// phase signal shows a wave (two periods in the burst), whole periods of it, at least two.
    /// The burst is healing + that window.
    bool window_auto = false;
    /// cpi.noisy_curvature (adaptive): how a jump's a posteriori curvature counts as truncation
    /// error when it lies within its own noise (mean_significance.hpp). ignored: not at all
    /// (judged 0); counted (what runs before the key did): its debiased norm; pooled (forward
    /// Euler without cpi.curvature = pooled), where that norm is positive: the debiased norm of
    /// the curvature fitted to the slopes of the pooled bursts and the burst after the jump
    /// (pooled_curvature.hpp; a norm that debiases to 0 is charged 0 in every mode), a
    /// baseline several jumps long whose noise is a fraction of the one jump's, so that an
    /// accelerating path's truncation, each jump's within its own noise, is still charged.
    /// A curvature resolved above its noise counts in every mode.
    enum class NoisyCurvature { ignored, counted, pooled };
    NoisyCurvature noisy_curvature = NoisyCurvature::ignored;
    /// cpi.curvature = pooled (forward Euler, the burst's own slope): every jump also adds
    /// omega b, the curvature b fitted to the slopes of the last `pool` accepted bursts (at
    /// least 3; estimators/pooled_curvature.hpp), when b is resolved above its noise
    /// (mean_significance.hpp); its noise is charged with the statistical part and the
    /// truncation part is what b leaves of the curvature measured after the jump. An
    /// accelerating trajectory's forward-Euler jumps each undershoot within their own noise,
    /// and all by the same sign (docs/error_control.md §3, "A curvature pooled over the bursts").
    /// false ("none"): forward Euler.
    bool pooled_curvature = false;
    /// The fewest bursts a pooled curvature is fitted to (two are Adams-Bashforth 2's line).
    static constexpr std::size_t curvature_min_bursts = 3;
    /// cpi.lift_error = counted (default): a kept jump's error includes the lift's own error in X
    /// (CoarseStepper::lift_error()), and the next DT plans for the last one (lift reserve);
    /// ignored: neither (a lift still fails when its error alone exceeds the tolerance).
    bool count_lift_error = true;
    /// cpi.lift = own: every jump lifts the members apart (CoarseStepper::lift_apart), member r
    /// moved by DT times its own slope's deviation from the ensemble slope (from the last
    /// accepted burst's window) on top of the common increment: a member that has stopped
    /// stays where it stopped, and the members' mean lands where the projection put it.
    bool lift_apart = false;
    /// cpi.accuracy (adaptive): the error the jumps may add to the whole trajectory, as a
    /// multiple of the ensemble's standard error (trajectory_budget.hpp); every jump's
    /// tolerance (control.tolerance is then only the first value) comes from it. NaN: off.
    double accuracy = std::numeric_limits<double>::quiet_NaN();
    /// cpi.accuracy: the lift keeps the members' spread (cpi.lift = members or own), so every
    /// accepted burst measures the ensemble's standard error; false (cpi.lift = mean, which
    /// lifts every realization onto one ICDF): only the first burst, before any lift, does.
    bool spread_survives_lift = false;
    double window_min = 0.0, window_max = 0.0;  ///< 0 < window_min <= window_max
    static constexpr double window_inefficiency_limit = 0.25;
    /// Bursts whose measurements the fast-noise constant averages (a running mean).
    static constexpr int window_evidence = 4;
};

class MultistepProjectiveIntegrator final : public ProjectiveIntegrator {
  public:
    /// \pre burst.healing >= 0, burst.window > 0, steps in {1, 2}, pooled slopes with steps = 1
    ///      and pool >= 1; adaptive: 0 < dt_min <=
    ///      dt_max finite, tolerance > 0, safety in (0, 1], growth > 1, max_rejections >= 0;
    ///      else dt >= 0.
    explicit MultistepProjectiveIntegrator(const MultistepSettings& settings,
                                           RepairHook repair = {});

    std::string_view name() const override;
    /// Adaptive: needs stepper.can_keep_state() and a stepper with members (slope standard
    /// errors); without members the step ends invalid_burst and says so.
    ProjectiveStepRecord step(CoarseStepper& stepper) override;
    /// Always a state (also before the first burst: an empty history).
    IntegratorState save_state() const override;
    /// nullopt (a checkpoint written by a single-step integrator, or of format 1): the state
    /// of a new integrator.
    void restore_state(const IntegratorState& state) override;

    const MultistepSettings& settings() const { return settings_; }
    /// Totals since the start of the run (saved with the state).
    using Totals = MultistepTotals;
    const Totals& totals() const { return totals_; }
    /// Adaptive: the run's controller in a few lines for the log and the run file: jumps kept,
    /// rejected, direct bursts, mean DT, the statistical share of the error, and the mean DT
    /// the tolerance would allow with 2 and 4 times the `realizations`.
    std::string summary(int realizations, long bursts) const override;

  private:
    /// One burst measured: its slope node, end state, decay estimate; false (and rec says
    /// why) when the burst cannot give a slope.
    struct Measured {
        SlopeNode node;
        double t_end = 0.0;
        Eigen::VectorXd x_end;
        DecayRateEstimate decay;
        /// Why no jump may start from this burst (empty: it may), and its kind (none: it may).
        std::string hold;
        DtLimit hold_kind = DtLimit::none;
        WindowNoise noise;  ///< cpi.window_auto: how the slope's noise falls with the window
        /// The period of a wave the realizations share (wave_coherence), NaN: none measured.
        double wave_period = std::numeric_limits<double>::quiet_NaN();
        /// cpi.lift = own: each member's slope minus the ensemble slope over the window.
        Eigen::MatrixXd member_deviation;
        /// The ensemble's standard error over the window (TrajectoryBudget::standard_error,
        /// RMS over its samples); NaN without members.
        double sigma = std::numeric_limits<double>::quiet_NaN();
        int realizations = 0;  ///< members of the burst's observable (0: none)
    };
    /// `length` <= 0: one burst (healing + window); longer: the healing grows.
    bool measure_burst(CoarseStepper& stepper, ProjectiveStepRecord& rec, Measured& out,
                       double length = 0.0) const;
    /// The length of a burst starting now (a direct one or the one after a jump): one burst, or
    /// the rest of the run when one burst would leave less than one more, so that the run ends
    /// at its end time rather than short of it.
    double burst_length_from(const CoarseStepper& stepper) const;
    /// Takes the burst's slope and end state; cpi.window_auto: sizes the next bursts' window
    /// from its evidence (into `c`).
    void accept_burst(const Measured& m, ControllerRecord& c);
    /// The estimation window of the bursts now: the burst less the current healing, or
    /// (cpi.window_auto) the window the evidence asks for.
    double window() const;
    /// The bursts' length now: healing + window.
    double burst_length() const { return healing_ + window(); }
    /// cpi.window_auto: the window of the next bursts from the accepted burst's evidence.
    void judge_window(const Measured& m, ControllerRecord& c);
    /// cpi.healing_auto: the healing of the next bursts from the burst after a lift at t_lift;
    /// the evidence goes into `c`.
    void judge_healing(const BurstSamples& burst, double t_lift, ControllerRecord& c);
    /// The drift rate a burst's phase signal is held back by: settings_.drift_rate, or with
    /// cpi.accuracy the trajectory's budget per burst once the ensemble's noise is measured.
    double drift_rate() const;
    /// The method's nodes (q_eff of them) and the error model of the next jump.
    std::vector<SlopeNode> method_nodes() const;
    /// What the next jump projects from: the method's nodes (cpi.slope = burst), or one pooled
    /// node with the covariance of its noise with the state's (pooled).
    struct JumpBasis {
        std::vector<SlopeNode> nodes;
        Eigen::VectorXd committed;  ///< empty: no burst reused
        PooledSlope pooled;         ///< the estimate it was made from (pooled.bursts() = m)
        /// cpi.curvature = pooled: the curvature the jump adds (empty: none, also when it is
        /// within its noise), and what was decided (for the step's message).
        PooledCurvature correction;
        std::string correction_note;
        JumpErrorModel model(double t0, double curvature) const {
            return {nodes, t0, curvature, 1.0, committed, correction};
        }
    };
    JumpBasis jump_basis() const;
    /// cpi.curvature = pooled: the curvature of the pool's bursts into `b` when resolved, and
    /// the note saying what was decided.
    void add_curvature_correction(JumpBasis& b) const;
    /// cpi.noisy_curvature = pooled: the debiased RMS of the curvature fitted to the pool's
    /// slopes and `after`'s (the burst after the jump); NaN while the pool holds fewer than 2.
    double pooled_noisy_curvature(const SlopeNode& after) const;
    /// The curvature the next jump's plan counts as truncation: NaN before q + 1 slopes; with a
    /// curvature correction in `basis`, what it leaves of the last two slopes' (curvature_left).
    double prior_curvature(const JumpBasis& basis) const;
    /// Asks the controller for the next DT and writes its plan into `rec`; returns DT.
    double plan_dt(ProjectiveStepRecord& rec, const JumpBasis& basis) const;
    /// cpi.accuracy: the next jump's tolerance from the trajectory's budget (into the
    /// controller), and the budget's record (into `c`); nothing without cpi.accuracy.
    void set_jump_tolerance(const JumpBasis& basis, ControllerRecord& c);
    /// cpi.accuracy: the ensemble mean's walk per unit time from the last accepted burst's slope
    /// (walk_rate()), charged per unit of DT beyond each jump's slope variance.
    double budget_walk() const;
    /// The record's statistical parts of a jump of `dt`: charged, the jump's own, and what one
    /// burst's slope and the whole pool would have given (ControllerRecord).
    void record_statistical(ControllerRecord& c, const JumpBasis& basis, double dt) const;

    MultistepSettings settings_;
    RepairHook repair_;
    std::deque<SlopeNode> history_;  ///< accepted slopes, oldest first (at most steps + 1)
    /// history_.front() is the first burst's earlier window: for the curvature, not projected from.
    bool curvature_only_front_ = false;
    double t_end_ = 0.0;                      ///< end of the last accepted burst
    Eigen::VectorXd x_end_;                   ///< X there
    DecayRateEstimate decay_;                 ///< from the last accepted burst
    std::string hold_;                        ///< why no jump may start from it (empty: one may)
    DtLimit hold_kind_ = DtLimit::none;       ///< fast_transient or in_phase_wave (none: one may)
    StepSizeController controller_;           ///< every rule on DT: plan, caps, accept/reject, redo
    std::optional<TrajectoryBudget> budget_;  ///< cpi.accuracy: the trajectory's error budget
    /// The accepted bursts' slopes and their commitments (kept with cpi.slope = burst too, to
    /// record what pooling would have given).
    SlopePool pool_;
    double healing_;  ///< the healing of the next burst (cpi.healing_auto: from the evidence)
    /// The last lift's error in X: the part of the next jump's tolerance planned for the lift.
    double lift_reserve_ = 0.0;
    /// The realizations of the last accepted burst (the significance test's degrees of freedom).
    int realizations_ = 0;
    double window_;  ///< cpi.window_auto: the window of the next burst
    /// cpi.window_auto: running mean of the bursts' fast-noise constant c (window_noise.hpp)
    /// over the last window_evidence measurements, and how many there were.
    double fast_time2_ = std::numeric_limits<double>::quiet_NaN();
    int noise_measurements_ = 0;
    /// cpi.lift = own: each member's slope minus the ensemble slope over the last accepted
    /// burst's window (R x dim; empty: none measured, the members move alike).
    Eigen::MatrixXd member_deviation_;
    Totals totals_;
};

}  // namespace efdem::coarse
