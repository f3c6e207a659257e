#pragma once
/// \file
/// How long a slope window must be: the evidence behind cpi.window_auto (docs/error_control.md
/// §7).
///
/// A burst buys one slope; what it costs is its length, healing h + window W. Over a whole run
/// the accumulated statistical error at a given speed-up is proportional to (h + W) V(W), the
/// variance of the window's slope times the DEM time spent on it. Two kinds of noise make V:
///
/// * the ensemble's own random walk (the slow coordinate's diffusion q): V = 1.2 q / W for a
///   least-squares slope. (h + W) V falls to its best value 1.2 q once W >> h.
/// * fast fluctuations about the slow path (variance s^2, correlation time tau << W):
///   V = 24 s^2 tau / W^3, whose share falls as 1 / W^2.
///
/// With V(W) = a / W + b / W^3, a burst's efficiency relative to the best one is
///
///     (h + W) V(W) / a = 1 + g(W),   g(W) = h / W + u (1 + h / W),   u = b / (a W^2),
///
/// and the two kinds are told apart by how the members' slopes correlate across windows: the
/// variance of their slopes over the window's two halves against the whole window's is
/// rho = V(W/2) / V(W) = (2 + 8 u) / (1 + u): 2 for a random walk (the whole window's slope is
/// the mean of two uncorrelated half-window slopes), 8 for fast noise alone (the whole window's
/// slope also uses the step between the halves' means). u = (rho - 2) / (8 - rho) measures the
/// fast part, and c = u W^2 [time^2] carries it to any other window. rho < 2 (the members'
/// half-window slopes positively correlated: a persistent part of each member's rate, which no
/// window averages out) is counted as a random walk, which errs towards longer windows.
/// cpi.window_auto takes the shortest window with g(W) <= 1/4: within 25 % of the best
/// efficiency, with the least DEM time per slope.

#include <limits>
#include <span>

#include <Eigen/Core>

namespace efdem::coarse {

struct WindowNoise {
    bool measured = false;  ///< false: < 2 realizations, or < 2 samples in a half of the window
    /// rho = V(W/2) / V(W): the members' half-window slopes' variance over the whole window's
    /// (about their ensemble means, pooled over the components).
    double ratio = std::numeric_limits<double>::quiet_NaN();
    /// Correlation of each member's two half-window slopes (about the ensemble means): ~0 for a
    /// random walk and for fast noise, positive for a persistent part of the members' rates.
    double correlation = std::numeric_limits<double>::quiet_NaN();
    /// c = u W^2: the fast noise's variance relative to the random walk's, carried to any
    /// window [time^2]; rho capped at 7.5 (u <= 11). Negative when rho < 2 (noise, or a
    /// persistent part): a mean over bursts stays unbiased; window_inefficiency() clamps it.
    double fast_time2 = std::numeric_limits<double>::quiet_NaN();
    double window = std::numeric_limits<double>::quiet_NaN();  ///< W measured over
};

/// The measurement above on the samples at t >= t_window (members: one R x dim matrix per
/// sample). \pre t strictly increasing, members.size() == t.size().
WindowNoise window_noise(std::span<const double> t, std::span<const Eigen::MatrixXd> members,
                         double t_window);

/// g(W) of the file comment for healing h and fast-noise constant c (c < 0 counts as 0).
double window_inefficiency(double window, double healing, double fast_time2);

/// The shortest window on the grid lo, lo + step, ..., hi with window_inefficiency <= limit;
/// hi when none is. \pre 0 < lo <= hi, step > 0, limit > 0.
double efficient_window(double healing, double fast_time2, double limit, double lo, double hi,
                        double step);

}  // namespace efdem::coarse
