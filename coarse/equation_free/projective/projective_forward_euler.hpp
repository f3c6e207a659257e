#pragma once
/// \file
/// Coarse projective forward Euler with a fixed step and a least-squares slope (physics.md §10,
/// paper case (a): healing 10, window 10, DT 80).

#include <string_view>

#include "coarse/equation_free/projective/projective_integrator.hpp"
#include "coarse/equation_free/projective/stability_monitor.hpp"

namespace efdem::coarse {

/// Settings of ProjectiveForwardEuler; times in sqrt(d_p/g). Defaults: paper case (a).
struct ProjectiveEulerSettings {
    BurstSettings burst;    ///< healing, window, what a flagged DT does
    double dt = 80.0;       ///< projective step DT (>= 0; 0 = burst only)
    int max_halvings = 10;  ///< halve_step: DT/2, ..., DT/2^max_halvings, then 0
};

/**
 * \brief X(t_n + dt_b + DT) = X(t_n + dt_b) + DT s_n, s_n the least-squares slope over the
 *        samples with t >= t_n + healing (physics.md §10).
 *
 * One step: run(healing + window); least-squares slope of the window; decay-rate estimate from
 * the two halves of the window and |G(lambda)| for DT (stability_monitor.hpp), acted on by the
 * policy; X_proj = X(t_end) + DT s from the raw last sample; repair hook; lift at t_end + DT.
 * With K inner forward-Euler steps of size h, healing = (K-1) h and window = h this is the
 * projective forward Euler of Gear & Kevrekidis with M = DT/h (physics.md §11.1).
 *
 * \code
 * ProjectiveForwardEuler pfe({.burst = {.healing = 10, .window = 10}, .dt = 80},
 *                            [&](Eigen::VectorXd& x) { return repair_monotone(x, z_lo, z_hi); });
 * const ProjectiveStepRecord rec = pfe.step(stepper);
 * if (!rec.advanced()) log::warn("{}: {}", to_string(rec.status), rec.message);
 * \endcode
 */
class ProjectiveForwardEuler final : public ProjectiveIntegrator {
  public:
    /// \pre burst.healing >= 0, burst.window > 0, dt >= 0 (all finite), max_halvings >= 0.
    explicit ProjectiveForwardEuler(const ProjectiveEulerSettings& settings,
                                    RepairHook repair = {});

    std::string_view name() const override { return "projective_forward_euler"; }
    ProjectiveStepRecord step(CoarseStepper& stepper) override;
    const ProjectiveEulerSettings& settings() const { return settings_; }

  private:
    ProjectiveEulerSettings settings_;
    RepairHook repair_;
};

}  // namespace efdem::coarse
