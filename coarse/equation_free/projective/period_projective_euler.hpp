#pragma once
/// \file
/// Coarse projective forward Euler over a whole number of travelling-wave periods, with the
/// period-mean slope (physics.md §9-§10, paper case (b): burst 30, DT = 2T).

#include <string_view>

#include "coarse/equation_free/estimators/period_estimator.hpp"
#include "coarse/equation_free/projective/projective_integrator.hpp"
#include "coarse/equation_free/projective/stability_monitor.hpp"

namespace efdem::coarse {

/// Settings of PeriodProjectiveEuler; times in sqrt(d_p/g). The period estimator's own
/// settings are a separate constructor argument.
struct PeriodProjectiveEulerSettings {
    /// Healing, the initial estimation window after it, what a flagged DT does (halve_step
    /// halves k).
    BurstSettings burst{.healing = 10.0, .window = 20.0};
    int periods_per_step = 2;     ///< k in DT = k T (>= 0; 0 = burst only)
    double max_extension = 30.0;  ///< most the burst may be lengthened to see enough periods
    double extension_step = 5.0;  ///< length of each extension (> 0)
};

/**
 * \brief DT = k T: X_proj = X(t_end) + k T s, with T measured in the burst and s the
 *        period-mean slope over the last two periods (physics.md §10, Q12, Q13).
 *
 * One step: run(healing + window); estimate T from the phase signal of the post-healing
 * samples (period_estimator.hpp); while fewer than `period.min_periods` full periods are seen,
 * run extension_step more, up to max_extension in total, then give up with status
 * too_few_periods (no jump, no lift). Then s = (mean over the last period - mean over the one
 * before)/T, exact for a periodic oscillation on a linear trend, and the jump from the *raw*
 * end-of-burst value over a whole number of periods, so the reused particle positions are at
 * the phase the projected state belongs to (§9). The stability monitor uses period means
 * (three periods needed; otherwise not assessed); halve_step halves k.
 *
 * \code
 * PeriodProjectiveEuler cpi({.burst = {.healing = 6, .window = 24}, .periods_per_step = 2});
 * const ProjectiveStepRecord rec = cpi.step(stepper);   // rec.period, rec.dt = 2 rec.period
 * \endcode
 */
class PeriodProjectiveEuler final : public ProjectiveIntegrator {
  public:
    /// \pre burst.healing >= 0, burst.window > 0, periods_per_step >= 0, max_extension >= 0,
    ///      extension_step > 0 (all finite); period.min_periods >= 2.
    explicit PeriodProjectiveEuler(const PeriodProjectiveEulerSettings& settings,
                                   RepairHook repair = {}, const PeriodSettings& period = {});

    std::string_view name() const override { return "period_projective_euler"; }
    ProjectiveStepRecord step(CoarseStepper& stepper) override;
    const PeriodProjectiveEulerSettings& settings() const { return settings_; }
    const PeriodSettings& period_settings() const { return period_; }

  private:
    PeriodProjectiveEulerSettings settings_;
    RepairHook repair_;
    PeriodSettings period_;
};

}  // namespace efdem::coarse
