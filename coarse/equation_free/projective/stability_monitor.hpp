#pragma once
/// \file
/// Stability monitoring of a projective step from the burst itself: estimate the decay rate of
/// the dominant transient in the post-healing window, evaluate the cycle's amplification
/// G(lambda) (projective_stability.hpp) for the planned DT, and flag DT before the jump.
///
/// Why: case (a) of the paper amplifies every mode with decay rate in (0.031, 0.182) per unit
/// time (physics.md §10, §12 item 12). Such a mode shows in the burst as a slope that shrinks
/// by e^(lambda delay) over the window; measuring that ratio costs nothing.

#include <limits>
#include <span>
#include <string>

#include <Eigen/Core>

#include "coarse/equation_free/projective/projective_stability.hpp"

namespace efdem::coarse {

/// What a projective integrator does when the monitor flags the planned DT.
enum class StabilityPolicy {
    warn,        ///< take the step anyway; the record carries the flag and the message
    halve_step,  ///< halve DT (DT = k T: halve k) until |G| <= 1, down to DT = 0 (no jump)
    stop         ///< take no jump; the record's status says why
};

/// A decay rate lambda from two slope estimates taken `delay` apart, or why there is none.
struct DecayRateEstimate {
    bool ok = false;
    /// lambda = ln(ratio)/delay [1/sqrt(d_p/g)]; negative for a decaying transient.
    double rate = 0.0;
    /// ratio = (s_early . s_late)/(s_early . s_early): the least-squares factor s_late/s_early.
    double ratio = 0.0;
    /// Time between the two slope estimates [sqrt(d_p/g)].
    double delay = 0.0;
    std::string message;
};

/**
 * \brief lambda from two slope vectors of the same transient: s_late = e^(lambda delay) s_early,
 *        fitted in least squares over the components.
 *
 * Not ok when s_early is zero, or when the ratio is <= 0 (the slope changes direction: an
 * oscillation or noise dominates and there is no single decay rate).
 * \pre early.size() == late.size(), delay > 0.
 */
DecayRateEstimate decay_rate_from_slopes(const Eigen::VectorXd& early, const Eigen::VectorXd& late,
                                         double delay);

/**
 * \brief lambda from least-squares slopes over the two halves of the window t >= t_start.
 *
 * For X = X_slow + v e^(lambda t), where v e^(lambda t) dominates the slope, the halves'
 * slopes satisfy s2/s1 = e^(lambda W/2) exactly when the samples are equally spaced (the two
 * halves are shifted copies of each other). A slope dominated by the slow drift gives
 * lambda ~ 0, i.e. nothing to flag. Not ok with fewer than two samples per half.
 * \pre as least_squares_slope().
 */
DecayRateEstimate estimate_decay_rate(std::span<const double> t, std::span<const Eigen::VectorXd> x,
                                      double t_start);

/// Whether the change of slope between the window's halves, which estimate_decay_rate() turns
/// into lambda, stands above the realizations' noise.
struct DecayResolution {
    bool measured = false;  ///< false: no members, or too few samples (nothing said)
    bool resolved = false;
    /// sum_i change_i^2 / sum_i se_i^2 (estimators/mean_significance.hpp): ~1 for noise alone.
    double statistic = std::numeric_limits<double>::quiet_NaN();
    /// Three standard deviations above 1 for noise alone (mean_significance.hpp).
    double threshold = std::numeric_limits<double>::quiet_NaN();
};

/**
 * \brief Every member's least-squares slopes over the same two halves of the window t >= t_start
 *        as estimate_decay_rate(); the ensemble's change of slope s_late - s_early against its
 * standard error from the members' own changes (mean_significance()). A rate from an unresolved
 *        change is the noise's, and must not shorten DT (docs/error_control.md §4).
 * \pre t strictly increasing; members one R x dim matrix per sample (else not measured).
 */
DecayResolution decay_resolution(std::span<const double> t,
                                 std::span<const Eigen::MatrixXd> members, double t_start);

/**
 * \brief lambda from period-mean slopes of the last two and the two periods before, for
 *        oscillating bursts: delay = T. Needs three periods in [t_start, t_end]; not ok
 *        otherwise.
 * \pre period > 0; as period_mean_slope().
 */
DecayRateEstimate estimate_decay_rate_periodic(std::span<const double> t,
                                               std::span<const Eigen::VectorXd> x, double period,
                                               double t_start, double t_end);

/// The monitor's verdict on one planned cycle.
struct StabilityAssessment {
    /// false: no decay rate could be measured; `stable` is then true by default.
    bool assessed = false;
    /// false: the measured mode decays (lambda < 0) but |G(lambda)| > 1 for the planned DT.
    bool stable = true;
    double rate = std::numeric_limits<double>::quiet_NaN();           ///< lambda
    double amplification = std::numeric_limits<double>::quiet_NaN();  ///< G(lambda)
    double exact = std::numeric_limits<double>::quiet_NaN();          ///< e^(lambda (dt_b + DT))
    std::string message;
};

/**
 * \brief Flags a cycle that would amplify the measured transient: lambda < 0 and
 *        |G(lambda)| > 1 (cpi_amplification()). Growing or undetected modes are not flagged:
 *        following a growing mode is the integrator's job, not an instability.
 */
StabilityAssessment assess_stability(const DecayRateEstimate& decay, const CpiCycle& cycle);

}  // namespace efdem::coarse
