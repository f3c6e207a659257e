#pragma once
/// \file
/// Is the micro model still in a fast transient? The expansion signal of a burst (for the DEM:
/// the number-weighted mean particle height, which demixing of equal spheres leaves unchanged
/// and which the bed's expansion after fluidization moves by several d_p; without one, the phase
/// signal) drifts while the fast transient lasts and only oscillates (travelling waves) or
/// fluctuates on the slow manifold. (The mass-weighted centre of mass is no such signal: heavy
/// particles sinking lower it — that is the slow dynamics.)
/// Judged from the run itself: the drift is the least-squares slope of the ensemble-mean phase
/// signal over a window; its noise the spread of the members' own slopes / sqrt(R).

#include <limits>
#include <string>

#include "coarse/equation_free/coarse_stepper.hpp"

namespace efdem::coarse {

struct PhaseDrift {
    bool measured = false;  ///< members' phase signals over >= 3 samples were available
    double slope = std::numeric_limits<double>::quiet_NaN();           ///< [unit per sqrt(d_p/g)]
    double standard_error = std::numeric_limits<double>::quiet_NaN();  ///< of the slope
    /// |slope| > 2 standard errors and > allowed_rate: still in the fast transient.
    bool drifting = false;
    std::string message;  ///< what was found, for the log
};

/**
 * \brief The drift of the expansion signal (BurstSamples::member_expansion, or member_phase
 *        when there is none) over the samples of `burst` with t >= t_start.
 *
 * `allowed_rate` (>= 0): a drift this slow is accepted even when it is significant (e.g. the
 * tolerance per window length: the phase signal moves less than the tolerance over a window).
 * Not measured (drifting false) without members' phase signals (BurstSamples::member_phase) or
 * with fewer than 3 samples or 2 members.
 */
PhaseDrift phase_drift(const BurstSamples& burst, double t_start, double allowed_rate);

/// Are the members' oscillations (travelling waves) in phase, so that the ensemble mean itself
/// oscillates? Realizations that all fluidize at t = 0 start their waves together and stay in
/// phase for a long time (the demo bed at U_s = 0.41: for all of its first 60 time units). Then
/// the ensemble slope over less than two periods is biased by the common wave, and the spread of
/// the members' slopes cannot see it (bench/wave_slope_bias.py).
struct WaveCoherence {
    bool measured = false;
    /// RMS of the detrended ensemble-mean phase signal over RMS(detrended members)/sqrt(R):
    /// ~1 for independent phases, sqrt(R) for members in phase.
    double ratio = std::numeric_limits<double>::quiet_NaN();
    double threshold = std::numeric_limits<double>::quiet_NaN();  ///< (1 + sqrt(R))/2
    /// Period of the ensemble-mean phase signal: NaN when no full period is seen or when two
    /// of it do not fit in the samples (then it was seen once, which is no evidence of a wave:
    /// at U_s = 0.19 on the tall bed, which has no waves, a slow common swing of the mean gave
    /// one "period" of 15.6 in a 20-unit burst, ratio 1.70 > 1.5 at R = 4, and held a jump).
    /// The waves the guard is for (T ~ 9 at U_s = 0.41) fit twice in bursts of 20-22.
    double period = std::numeric_limits<double>::quiet_NaN();
    /// ratio > threshold **and** the ensemble mean oscillates (a period was measured). Members
    /// that move together without oscillating are no wave: after a lift every realization
    /// relaxes from the same colour perturbation, and the shared relaxation (one bend, at most
    /// one upward crossing of its trend line) lifts the ratio above the threshold at U_s = 0.19,
    /// where there are no waves (measured: 2.17-2.24 > 1.9 at R = 8). That relaxation is the
    /// healing's business, not a bias of the slope the guard is for.
    bool in_phase = false;
    std::string message;
};

/// Wave coherence over the samples of `burst` with t >= t_start (linear trends removed per
/// member). Not measured without members' phase signals, with < 2 members or < 8 samples.
/// in_phase needs both a coherent ensemble mean and a measured period (see in_phase).
WaveCoherence wave_coherence(const BurstSamples& burst, double t_start);

}  // namespace efdem::coarse
