#pragma once
/// \file
/// Period of the travelling-wave oscillation seen in a burst (physics.md §7, Q12).

#include <limits>
#include <span>
#include <string>
#include <vector>

namespace efdem::coarse {

struct PeriodSettings {
    /// Full periods (intervals between consecutive upward zero crossings) needed for an ok
    /// estimate; Q12 asks for two after the healing part of the burst.
    int min_periods = 2;
    /// Half-width of the crossing detector's hysteresis band, as a fraction of the RMS of the
    /// detrended signal (0.3 RMS = 0.21 amplitude for a sine). Noise smaller than the band
    /// cannot create or remove a crossing. In (0, 1).
    double hysteresis = 0.3;
    /// Passes that re-detrend with a line fitted jointly with the oscillation (0: plain
    /// least-squares detrending only); see estimate_period().
    int refinements = 3;
    /// Harmonics of the current period estimate fitted together with the trend line in each
    /// refinement pass (1 suffices for a sine; travelling-wave signals are not sinusoidal).
    int harmonics = 2;
};

enum class PeriodStatus {
    ok,              ///< at least min_periods full periods seen
    too_few_periods  ///< fewer (or no oscillation at all); lengthen the burst
};

struct PeriodEstimate {
    PeriodStatus status = PeriodStatus::too_few_periods;
    /// Mean spacing of the upward zero crossings [sqrt(d_p/g)]; NaN with fewer than two
    /// crossings.
    double period = std::numeric_limits<double>::quiet_NaN();
    /// Full periods seen: number of crossings - 1 (0 if none).
    int n_periods = 0;
    /// Upward zero-crossing times of the detrended signal, linearly interpolated.
    std::vector<double> crossings;
    /// Why the status is not ok (empty when ok).
    std::string message;

    bool ok() const { return status == PeriodStatus::ok; }
};

/**
 * \brief Period of an oscillating scalar signal on top of a linear trend (physics.md §7, Q12).
 *
 * 1. Subtract the least-squares line of the whole series.
 * 2. Find upward zero crossings with a Schmitt trigger: armed when the detrended value is
 *    <= -h, fired when it reaches +h; the crossing time is the linearly interpolated last
 *    upward sign change before firing. h = settings.hysteresis * RMS(detrended). At the window
 *    edges, where the band cannot frame a crossing, a start below zero arms and a pending sign
 *    change counts if the signal ends above zero.
 * 3. T = (last crossing - first crossing)/(number of crossings - 1).
 * 4. Refinement: a least-squares line alone, over a window that is not a whole number of
 *    periods, leaves a slope of up to ~(6/pi) a/(n^2 T) in the residual (amplitude a, n
 *    periods), which shifts successive crossings and biases T by up to ~0.3/n^2 relatively
 *    (3 % at n = 3). So, once two periods are seen, the trend is re-fitted jointly with the
 *    first settings.harmonics harmonics of the current T (harmonic regression: the oscillation
 *    can no longer leak into the slope) and steps 2-3 are repeated. For a sine plus a linear
 *    trend only the crossing interpolation error is then left, O(w^2 h^3) per crossing for
 *    samples at spacing h (w = 2 pi/T).
 *
 * The signal is typically the centre-of-mass height, or the ICDF median, over the post-healing
 * part of a burst. status is too_few_periods (with a message) below settings.min_periods.
 * \pre t strictly increasing, signal.size() == t.size() >= 2, signal finite.
 */
PeriodEstimate estimate_period(std::span<const double> t, std::span<const double> signal,
                               const PeriodSettings& settings = {});

}  // namespace efdem::coarse
