#pragma once
/// \file
/// Where DT is chosen (docs/error_control.md §4): the error a jump of DT adds, from the slope
/// model of multistep_projection.hpp; the largest DT whose error stays within a target; and
/// StepSizeController, which holds every rule of adaptive CPI on DT — the caps (dt_min, dt_max,
/// growth, the first jump, the end of the run, stability), accept or reject, the rejection cap
/// and the redo rule. The multistep integrator only measures (burst -> slope), asks plan(),
/// projects and lifts, and asks judge(). Times in sqrt(d_p/g); errors RMS over the coarse
/// vector's components (d_p for the ICDF).
///
/// \code
/// StepSizeController c({.control = {.tolerance = 0.05, .dt_min = 10, .dt_max = 160},
///                       .burst = 20, .window = 10});
/// const DtPlan p = c.plan({.model = prior, .decay = decay, .end_time = 400});
/// // ... jump p.dt, run the next burst, measure the a posteriori error ...
/// const JumpVerdict v = c.judge(p.dt, error, posterior);   // v.accepted, c.state().dt_cap
/// \endcode

#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/estimators/pooled_curvature.hpp"
#include "coarse/equation_free/projective/multistep_projection.hpp"
#include "coarse/equation_free/projective/stability_monitor.hpp"

namespace efdem::coarse {

/// What the error of the next jump depends on.
struct JumpErrorModel {
    /// The method's nodes (q of them: 1 forward Euler, 2 Adams-Bashforth 2), oldest first.
    std::vector<SlopeNode> nodes;
    double t0 = 0.0;  ///< the jump starts here (end of the last burst)
    /// |D|, the noise-free RMS of the q-th divided difference of the slope; NaN while fewer
    /// than q + 1 slopes have been measured (the truncation part is then unknown, counted 0).
    double curvature = std::numeric_limits<double>::quiet_NaN();
    /// Factor on every standard error: 1/sqrt(k) for k times the realizations.
    double se_scale = 1.0;
    /// A pooled slope (one node, slope_pool.hpp): c, the covariance per unit DT of its noise
    /// with the noise earlier jumps put into the state; the statistical part is then the
    /// growth of the accumulated error, sqrt(DT^2 se^2 + 2 DT c). Empty: no reuse (c = 0).
    Eigen::VectorXd committed;
    /// cpi.curvature = pooled (forward Euler, one node, no pooled slope): the curvature b the
    /// jump adds, omega b with omega = integral_{t0}^{t0+DT} (t - tau) dt; its noise joins the
    /// statistical part, sqrt(DT^2 se^2 + omega^2 Var(b) + 2 DT omega Cov(b, s)), and
    /// `curvature` is then what b leaves (pooled_curvature.hpp). Empty: no correction.
    PooledCurvature correction;
};

/// The two parts of a jump's error (RMS over components).
struct JumpError {
    double statistical = 0.0;  ///< RMS of sqrt(sum_k W_k^2 se_k^2 (+ 2 W c, pooled))
    double truncation = 0.0;   ///< |D| |integral omega|
    /// How far the lift left the micro model's mean from the projected X (RMS): the burst after
    /// the jump measures curvature from where the lift put the state, so this part is not in
    /// the other two.
    double lift = 0.0;
    double total() const { return statistical + truncation + lift; }
};

/// "statistical s, truncation t[, lift l]" (the lift only when > 0): the parts of a jump's error
/// as the rejection message and the step report write them.
std::string error_parts(double statistical, double truncation, double lift);

/// Per component, the statistical part of a jump of `dt` under `model` (before se_scale):
/// sqrt(sum_k W_k^2 se_k^2), or for a pooled slope the charged sqrt(DT^2 se^2 + 2 DT c), with
/// a curvature correction sqrt(DT^2 se^2 + omega^2 Var(b) + 2 DT omega Cov(b, s)).
/// \pre dt >= 0, model.nodes non-empty.
Eigen::VectorXd statistical_error(const JumpErrorModel& model, double dt);

/// The error of a jump of `dt` under `model`. \pre dt >= 0, model.nodes non-empty.
JumpError jump_error(const JumpErrorModel& model, double dt);

/// The largest DT in [0, cap] with jump_error(model, DT).total() <= target (the error grows
/// monotonically with DT; bisection to 1e-6 relative). 0 when even tiny jumps exceed it only
/// if target <= 0. \pre target >= 0, cap >= 0 finite.
double largest_dt_within(const JumpErrorModel& model, double target, double cap);

/// What set a step's DT (ControllerRecord::limited_by). Its text (to_string) is written to the
/// run file (/cpi/controller/limited_by), the step log line and the progress line, and must
/// not change: run files are compared byte for byte.
enum class DtLimit {
    none,                     ///< "": not a step of the multistep integrator
    fixed,                    ///< "fixed": adaptive = false, DT = cpi.dt
    first_burst,              ///< "first burst": the run's first step measures the first slope
    tolerance,                ///< "tolerance": the largest DT within safety x tolerance
    dt_max,                   ///< "dt_max"
    first_jump_dt,            ///< "first jump (cpi.dt)"
    first_jump_no_curvature,  ///< "first jump (no curvature measured yet)": one burst
    growth,                   ///< "growth": growth x the last kept DT
    rejection,                ///< "rejection": the cap the last rejection set
    end_of_run,               ///< "end of run"
    below_dt_min,             ///< "tolerance below dt_min": one burst of direct simulation
    stability,                ///< "stability": halved until the measured transient is stable
    fast_transient,           ///< "fast transient": no jump from this burst (phase drift)
    in_phase_wave,            ///< "in-phase wave": no jump from this burst (common wave)
    jump_until,               ///< "cpi.jump_until": no jump ends later; then bursts only
};

/// The recorded text of `limit` (see DtLimit).
std::string_view to_string(DtLimit limit);
/// The DtLimit whose text is `text`; nullopt for any other text.
std::optional<DtLimit> dt_limit_from_string(std::string_view text);

/// The step-size controller's settings. Times in sqrt(d_p/g); tolerance in the coarse
/// vector's unit (d_p for the ICDF), RMS over its components.
struct StepSizeSettings {
    double tolerance = 0.05;  ///< error one jump may add (> 0)
    double dt_min = 10.0;     ///< smallest jump worth making (> 0)
    double dt_max = 160.0;    ///< largest jump (>= dt_min)
    double safety = 0.8;      ///< DT is planned for safety x tolerance (in (0, 1])
    double growth = 2.0;      ///< DT_next <= growth x DT_last (> 1)
    int max_rejections = 4;   ///< consecutive rejections after which a jump is kept anyway
};

/// How a StepSizeController is set up: the settings and the frame of the cycle it plans.
struct StepSizeSetup {
    StepSizeSettings control;
    /// false: DT = fixed_dt for every jump (shortened only at the end of the run), every jump
    /// kept; the controller only records.
    bool adaptive = true;
    double fixed_dt = 80.0;  ///< adaptive = false: the projective step (>= 0)
    /// adaptive: the first jump is at most this; NaN: planned from the tolerance when the first
    /// burst measured a curvature, else one burst, but at least dt_min.
    double first_dt = std::numeric_limits<double>::quiet_NaN();
    /// adaptive: DT is rounded down to a whole multiple of this (the sampling interval, so
    /// that bursts stay on the sampling grid and the run ends at its end time; 0: no rounding).
    double dt_quantum = 0.0;
    double burst = 20.0;   ///< healing + window: the burst that follows every jump (> 0)
    double window = 10.0;  ///< the slope's estimation window (the stability monitor's cycle)
    /// How the slope is fitted over that window (the stability monitor's cycle): least squares
    /// or the increment (cpi.slope_fit).
    SlopeEstimator estimator = SlopeEstimator::least_squares;
};

/// What plan() looks at: the state after the last accepted burst.
struct PlanInput {
    /// The method's nodes, t0 = the end of the last accepted burst, the curvature measured
    /// from the slopes before the jump (predicted truncation).
    JumpErrorModel model;
    DecayRateEstimate decay;  ///< measured in the last accepted burst (stability)
    /// fast_transient or in_phase_wave: no jump may start from that burst (hold_message says
    /// why); none: one may.
    DtLimit hold = DtLimit::none;
    std::string hold_message;
    double end_time = std::numeric_limits<double>::infinity();  ///< the run ends here
    /// cpi.jump_until: no jump ends later than this; from it on every step is a burst of
    /// direct simulation (infinite: no such time).
    double jump_end = std::numeric_limits<double>::infinity();
    /// The part of the tolerance the lift is expected to spend (the last lift's error in X,
    /// JumpError::lift), planned for so that the jump is not rejected for it; at most half of
    /// safety x tolerance is reserved, so a jump can always be planned.
    double lift_reserve = 0.0;
};

/// What plan() decided.
struct DtPlan {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    double dt = 0.0;  ///< the jump; 0: no jump, one burst of direct simulation
    DtLimit limited_by = DtLimit::none;
    /// Largest DT the tolerance allows with the realizations run, and with 2 and 4 times as
    /// many (NaN when not planned from the tolerance).
    double dt_tolerance = nan, dt_tolerance_2r = nan, dt_tolerance_4r = nan;
    /// The stability monitor's verdict on the DT taken (or the last one refused); none when
    /// the monitor was not asked.
    std::optional<StabilityAssessment> stability;
    std::string message;  ///< why there is no jump, when that needs saying (else empty)
};

/// What judge() decided on a jump, after the burst that followed it.
struct JumpVerdict {
    bool accepted = true;
    /// A kept jump above the tolerance (why it was kept), or the rejection; else empty.
    std::string message;
};

/// The controller's memory between two steps (saved in a checkpoint).
struct StepSizeState {
    double dt_last = std::numeric_limits<double>::quiet_NaN();  ///< last kept DT (NaN: none)
    double dt_cap = std::numeric_limits<double>::infinity();    ///< set by a rejection
    long consecutive_rejections = 0;
};

class StepSizeController {
  public:
    /// \pre adaptive: 0 < dt_min <= dt_max finite, tolerance > 0 finite, safety in (0, 1],
    ///      growth > 1, max_rejections >= 0; else fixed_dt >= 0 finite. burst > 0.
    explicit StepSizeController(const StepSizeSetup& setup);

    /**
     * \brief The next jump's DT. Adaptive, in this order: no jump from a held burst; the
     *        largest DT within safety x tolerance (at most dt_max); the first jump (cpi.dt, or
     *        one burst while no curvature is known); growth x the last kept DT; the rejection
     *        cap; rounded down to dt_quantum; no jump when this step's burst is the run's last;
     *        below dt_min no jump; the end of the run (the jump leaves exactly one burst);
     *        halved until stable (0 below dt_min). Fixed: fixed_dt, shortened at the end.
     */
    DtPlan plan(const PlanInput& in) const;

    /**
     * \brief Accept or reject a jump of `dt` whose error, measured after it, is `error`;
     *        `posterior` is the error model with the curvature the burst after the jump showed.
     *
     * Accepted when error <= tolerance, at dt_min, after max_rejections rejections in a row,
     * or when not adaptive; the caps are then lifted. Rejected (or `forced_reject`, tests):
     * the next attempt is capped at min(the DT the posterior allows for safety x tolerance,
     * DT/2), at least dt_min — or 0 (no jump, one burst directly) when the posterior allows
     * none >= dt_min; a forced rejection caps at DT/2.
     */
    JumpVerdict judge(double dt, const JumpError& error, const JumpErrorModel& posterior,
                      bool forced_reject = false);

    /// A jump of `dt` could not be made or measured (infeasible projection, invalid burst),
    /// or is to be taken as rejected (tests): the next attempt jumps at most dt/2.
    void jump_failed(double dt);
    /// A burst of direct simulation ran instead of a jump: the rejection cap is lifted.
    void direct_burst_done();

    const StepSizeSetup& setup() const { return setup_; }
    const StepSizeState& state() const { return state_; }
    void restore(const StepSizeState& state) { state_ = state; }
    /// cpi.window_auto: the bursts from now on are `burst` long with a `window` (their end-of-run
    /// room and stability cycle). \pre 0 < window <= burst.
    void set_burst(double burst, double window);
    /// cpi.accuracy: the tolerance of the jumps from now on (trajectory_budget.hpp).
    /// \pre tolerance > 0 finite.
    void set_tolerance(double tolerance);

  private:
    StepSizeSetup setup_;
    StepSizeState state_;
};

}  // namespace efdem::coarse
