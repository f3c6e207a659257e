#pragma once
/// \file
/// CpiSettings: the scene's `cpi.*` keys that the coarse run loop (projective_run.hpp)
/// and its integrator read, filled straight into the integrators' own settings (no copy of
/// them is kept anywhere else). `cpi.observable` names the coarse variable and is read by the
/// demixing room (coarse/demixing/observable_table.hpp). Times in sqrt(d_p/g).
///
// clang-format off
/// | key               | meaning                                                       | default |
/// |-------------------|---------------------------------------------------------------|---------|
/// | cpi.projection    | `fixed` (DT = cpi.dt), `periods` (DT = k T) or `adaptive`     | fixed   |
/// | cpi.integrator    | `euler` or `adams_bashforth2` (fixed, adaptive)               | euler   |
/// | cpi.warmup        | direct simulation before the first coarse step (lower bound)  | 0       |
/// | cpi.warmup_until  | `time` (cpi.warmup exactly) or `steady`: on until the phase    | adaptive:|
/// |                   | signal (bed centre of mass) no longer drifts (phase_drift.hpp) | steady  |
/// | cpi.warmup_max    | steady: most time the warm-up may run beyond cpi.warmup       | 10 burst|
/// | cpi.healing       | start of each burst left out of the slope                     | 10      |
/// | cpi.window        | estimation window after healing (>= 3 samples)                | 10      |
/// | cpi.dt            | projective step DT (projection = fixed)                       | 80      |
/// | cpi.periods       | k in DT = k T (projection = periods)                          | 2       |
/// | cpi.max_extension | most a burst may be lengthened to see 2 periods               | 30      |
/// | cpi.stability     | `warn`, `halve` or `stop` when DT is flagged                  | warn    |
/// | cpi.tolerance     | adaptive: error one jump may add, RMS over the ICDF [d_p]     | required|
/// |                   | (unless cpi.accuracy)                                         |         |
/// | cpi.accuracy      | adaptive, instead of cpi.tolerance: the error the jumps may   | none    |
/// |                   | add to the whole trajectory, in ensemble standard errors      |         |
/// |                   | (trajectory_budget.hpp; warm-up then by time by default)      |         |
/// | cpi.dt_min        | adaptive: shortest jump; below it a burst runs directly       | burst/2 |
/// | cpi.dt_max        | adaptive: longest jump                                        | 8 burst |
/// | cpi.safety        | adaptive: DT is planned for safety x tolerance                | 0.8     |
/// | cpi.growth        | adaptive: DT_next <= growth x DT_last                         | 2       |
/// | cpi.slope         | `burst` (the last burst's slope) or `pooled` (the weighted     | burst   |
/// |                   | mean of the last cpi.pool bursts', estimators/slope_pool.hpp; |         |
/// |                   | euler, fixed or adaptive)                                     |         |
/// | cpi.pool          | the last bursts a pooled slope or curvature uses (1..64)      | 4       |
/// | cpi.slope_fit     | `least_squares` over the window, or the window's `increment`  | least_  |
/// |                   | (the best where the noise is a walk, error_control.md §7;     | squares |
/// |                   | fixed or adaptive, not with cpi.window_auto)                  |         |
/// | cpi.curvature     | `none` (forward Euler) or `pooled`: each jump also adds the   | none    |
/// |                   | curvature fitted to the last cpi.pool (>= 3) bursts' slopes,  |         |
/// |                   | where resolved (estimators/pooled_curvature.hpp; euler, fixed |         |
/// |                   | or adaptive, cpi.slope = burst, not cpi.lift = own)           |         |
/// | cpi.healing_auto  | heal for cpi.healing only while bursts after a lift show a    | false   |
/// |                   | transient, else for a tenth of the burst (post_lift_transient) |         |
/// | cpi.window_auto   | adaptive: the window of the next bursts from how the slope's  | false   |
/// |                   | noise falls with the window (estimators/window_noise.hpp)     |         |
/// | cpi.window_max    | adaptive: the longest window cpi.window_auto may choose       | 4 burst |
/// | cpi.noisy_curvature | adaptive: a posteriori curvature within its noise `ignored` | ignored |
/// |                   | or `counted` as truncation error (runs before it: counted), or |         |
/// |                   | `pooled`: the curvature fitted to the pool's slopes instead   |         |
/// | cpi.finish        | `duration` (run to run.duration); `at_rest`: end where every  | duration|
/// |                   | realization is at rest; `steady`: there, or where the pooled  |         |
/// |                   | slope is noise (DriftTest, projective_run.hpp)                |         |
// clang-format on
///
/// With `adaptive`, cpi.dt (if given) caps the first jump (default: planned from the tolerance
/// when healing >= window gives the first burst a curvature, else one burst) and the keys of
/// `periods` are refused; the adaptive keys are refused with the other projections.
/// warmup, healing, window and max_extension must be whole multiples of the sampling interval.

#include <limits>
#include <memory>

#include "coarse/equation_free/projective/multistep_projective_integrator.hpp"
#include "coarse/equation_free/projective/period_projective_euler.hpp"
#include "coarse/equation_free/projective/projective_forward_euler.hpp"
#include "coarse/equation_free/projective/projective_integrator.hpp"
#include "core/param_table.hpp"

namespace efdem::coarse {

/// The drift rate of the phase signal (the bed's centre of mass, in the unit of the coarse
/// vector: d_p) below which a burst counts as on the slow manifold: cpi.tolerance per burst
/// length, i.e. over one burst the phase signal moves less than the error one jump may add.
/// Used twice with cpi.projection = adaptive: by the warm-up (cpi.warmup_until = steady) and by
/// the integrator, which makes no jump from a burst drifting faster (MultistepSettings::
/// drift_rate). A derivation rather than a key of its own: it has the tolerance's unit and
/// meaning ("small enough not to matter to one jump"), so a tighter tolerance asks for a
/// steadier start and a steadier burst with nothing else to keep consistent by hand
/// (docs/error_control.md §6).
double steady_drift_rate(double tolerance, double burst);

struct CpiSettings {
    enum class Projection { fixed, periods, adaptive } projection = Projection::fixed;
    /// 1: forward Euler; 2: Adams-Bashforth 2 (cpi.integrator).
    int steps = 1;
    /// Direct simulation before the first coarse step (the packed start is not on the slow
    /// manifold).
    double warmup = 0.0;
    /// Warm-up on evidence: after `warmup`, go on in windows until the phase signal's drift is
    /// within its noise (or slower than `drift_rate`), at most `warmup_max` longer.
    bool warmup_until_steady = false;
    double warmup_max = 0.0;
    /// The warm-up's drift threshold: a drift of the phase signal this slow (and within its
    /// noise) counts as steady [unit per sqrt(d_p/g)]. Derived, not a key:
    /// steady_drift_rate(cpi.tolerance, burst) with cpi.projection = adaptive (the same
    /// threshold the integrator holds a jump back by, multistep.drift_rate); 0 otherwise (no
    /// tolerance: steady only when the drift is within its noise).
    double warmup_drift_rate = 0.0;
    /// cpi.finish = steady or at_rest: the run ends after the first coarse step whose last sample
    /// finds the stepper at an end state (CoarseStepper::end_state_since: every realization at
    /// rest), with the time it was reached in the end status.
    bool finish_at_end_state = false;
    /// cpi.finish = steady: also after the coarse step at which the drift test calls a moving
    /// ensemble statistically steady (DriftTest, projective_run.hpp).
    bool finish_on_drift = false;
    /// cpi.jump_until: no jump ends later than this long after the run's start; from there on
    /// every coarse step is a burst of direct simulation (no jump, no lift), so that beds can
    /// come to rest as in a direct run (infinite: jumps to the end).
    double jump_until = std::numeric_limits<double>::infinity();
    /// Projection = fixed: healing, window, DT, stability policy.
    ProjectiveEulerSettings fixed;
    /// Projection = periods: healing, window, k, burst extension, stability policy.
    PeriodProjectiveEulerSettings periods;
    /// Projection = adaptive, or fixed with Adams-Bashforth 2.
    MultistepSettings multistep;

    /// Reads the keys above from the `cpi` scope (in the order of the table). Both
    /// projections' keys are read, so that switching cpi.projection on the command line works on
    /// a scene written for the other one. `sample_interval`: the stepper's sampling interval,
    /// which the times must be whole multiples of (its key is `observe.interval`).
    /// `for_cpi_run` false (a direct run of a cpi scene): the keys are read and their values
    /// range-checked, but not checked against the sampling grid, and none is required.
    static CpiSettings from_params(const Params& cpi, double sample_interval,
                                   bool for_cpi_run = true);

    /// healing + window of the selected projection: the length of an unextended burst.
    double burst() const;
    /// The estimation window of the selected projection.
    double window() const;
    /// The integrator these settings select, with `repair` applied to every projected vector.
    std::unique_ptr<ProjectiveIntegrator> make_integrator(RepairHook repair) const;
};

}  // namespace efdem::coarse
