#pragma once
/// \file
/// Coarse slope estimators: dX/dt from the samples of a burst (physics.md §10).
///
/// A time series is a list of sample times t_k (strictly increasing, in sqrt(d_p/g)) and values
/// X_k (Eigen vectors of one size, or scalars); every component gets its own slope. Window ends
/// are compared with the sample times to within time_tolerance(), so that a sample time built by
/// repeated addition of a sampling interval still counts as "at" the window start.

#include <cstddef>
#include <span>
#include <string>

#include <Eigen/Core>

namespace efdem::coarse {

/// Tolerance for comparing a sample time with a window end: 1e-9 max(1, |t|) [sqrt(d_p/g)].
double time_tolerance(double t);

/// Index of the first sample with t_k >= t_start - time_tolerance(t_start); t.size() if none.
std::size_t first_sample_at_or_after(std::span<const double> t, double t_start);

/// A slope estimate, or why there is none.
struct SlopeEstimate {
    bool ok = false;
    /// dX/dt per component [unit of X per sqrt(d_p/g)]; empty when !ok.
    Eigen::VectorXd slope;
    /// Samples that entered the estimate and the times they span.
    Eigen::Index n_samples = 0;
    double t_first = 0.0;
    double t_last = 0.0;
    /// Mean time of those samples: where a least-squares slope belongs (exact for a quadratic).
    double t_mean = 0.0;
    /// Why there is no estimate (empty when ok).
    std::string message;
};

/**
 * \brief Least-squares slope over the samples with t_k >= t_start (physics.md §10):
 *        s = sum_k (t_k - tbar)(X_k - Xbar) / sum_k (t_k - tbar)^2, per component.
 *
 * Exact for a linear X(t). With independent noise sigma_X per sample, Var(s) =
 * 12 sigma_X^2 (n-1)/(W^2 n (n+1)) for n samples spanning W. Not ok (with a message) when fewer
 * than two samples lie in the window. Two-pass sums (means first), so a large time offset does
 * not cost precision.
 * \pre t strictly increasing; x.size() == t.size(); all x_k of one size.
 */
SlopeEstimate least_squares_slope(std::span<const double> t, std::span<const Eigen::VectorXd> x,
                                  double t_start);

/**
 * \brief Increment slope over the samples with t_k >= t_start: s = (X_last - X_first) /
 *        (t_last - t_first), per component, placed at the window's middle (t_mean).
 *
 * Exact for a linear X(t), and the best linear unbiased slope when the noise is a walk (a
 * Brownian motion of diffusivity q: Var(s) = q / W for a window W, where least squares has
 * 1.2 q / W); with independent noise sigma_X per sample it has Var(s) = 2 sigma_X^2 / W^2, worse
 * than least squares for more than a few samples (docs/error_control.md §7). Not ok (with a
 * message) when fewer than two samples lie in the window.
 * \pre t strictly increasing; x.size() == t.size(); all x_k of one size.
 */
SlopeEstimate increment_slope(std::span<const double> t, std::span<const Eigen::VectorXd> x,
                              double t_start);

/// How a burst's window becomes a slope (cpi.slope_fit): least squares (the default) or the
/// window's increment.
enum class SlopeFit { least_squares, increment };

/// least_squares_slope() or increment_slope(), as FIT says.
SlopeEstimate window_slope(SlopeFit fit, std::span<const double> t,
                           std::span<const Eigen::VectorXd> x, double t_start);

/// Var(slope) W / q of a walk of diffusivity q over a window W: 1.2 for least squares (dense
/// samples), 1 for the increment.
double walk_slope_variance_factor(SlopeFit fit);

/// Least-squares line y ~ mean_value + slope (t - mean_time) of a scalar series.
struct LineFit {
    double slope = 0.0;
    double mean_time = 0.0;
    double mean_value = 0.0;
    double at(double time) const { return mean_value + slope * (time - mean_time); }
};

/// Least-squares line through all samples of a scalar series (same formula as above).
/// \pre t.size() == y.size() >= 2, t strictly increasing.
LineFit fit_line(std::span<const double> t, std::span<const double> y);

/**
 * \brief Time average over [a, b] of the piecewise-linear interpolant of (t_k, X_k):
 *        (1/(b - a)) * integral_a^b X(t) dt, integrated exactly (trapezoids between samples,
 *        linear interpolation at a and b).
 * \pre t strictly increasing with >= 2 samples; t_0 <= a < b <= t_last (to time_tolerance).
 */
Eigen::VectorXd interval_mean(std::span<const double> t, std::span<const Eigen::VectorXd> x,
                              double a, double b);
/// Scalar version of interval_mean().
double interval_mean(std::span<const double> t, std::span<const double> y, double a, double b);

/**
 * \brief Period-mean slope (physics.md §10, Q13):
 *        s = (<X>_[t_end - T, t_end] - <X>_[t_end - 2T, t_end - T]) / T,
 *        with <.> the exact interval_mean() of the interpolated samples.
 *
 * For X(t) = P(t) + X0 + beta t with P T-periodic, the continuous estimator returns beta
 * exactly, for any phase. With samples at spacing h it stays exact (to round-off) whenever the
 * interpolant of P is itself T-periodic, i.e. T is a multiple of h, wherever the sample grid
 * lies relative to t_end. Otherwise the interpolation error of a sine of amplitude a and
 * angular frequency w = 2 pi/T bounds the error by a w^2 h^2 / (4 T) (each mean is off by at
 * most a w^2 h^2/8). Compare least squares over two periods: a phase-dependent bias up to
 * 0.477 a/T.
 *
 * Not ok (with a message) when the samples do not cover [t_end - 2T, t_end].
 * \pre period > 0; t strictly increasing; x.size() == t.size().
 */
SlopeEstimate period_mean_slope(std::span<const double> t, std::span<const Eigen::VectorXd> x,
                                double period, double t_end);

/**
 * \brief Every member's own least-squares slope over the same window as
 *        least_squares_slope(t, x, t_start), from the members' coarse vectors
 *        (BurstSamples::members: one R x dim matrix per sample, row r = member r).
 *
 * Returns R x dim (row r = member r's slope); empty when there are no members (members empty,
 * or not one matrix per sample), when the matrices differ in shape, or when the window holds
 * fewer than two samples. The mean of the rows is the slope of the members' mean (least
 * squares is linear in X).
 * \pre t strictly increasing.
 */
Eigen::MatrixXd member_least_squares_slopes(std::span<const double> t,
                                            std::span<const Eigen::MatrixXd> members,
                                            double t_start);

/// Every member's own window_slope(fit, t, x, t_start), R x dim; empty as for
/// member_least_squares_slopes().
Eigen::MatrixXd member_window_slopes(SlopeFit fit, std::span<const double> t,
                                     std::span<const Eigen::MatrixXd> members, double t_start);

/// Every member's own period_mean_slope(t, x, period, t_end) (the same period T for all, each
/// member's own period means), R x dim; empty as for member_least_squares_slopes() or when the
/// samples do not cover two periods.
Eigen::MatrixXd member_period_mean_slopes(std::span<const double> t,
                                          std::span<const Eigen::MatrixXd> members, double period,
                                          double t_end);

/**
 * \brief Standard error of the ensemble slope from the members' own slopes (R x dim):
 *        SE_i = std_r(s_{r,i}) / sqrt(R), with the unbiased std (divisor R - 1).
 *
 * The members are independent realizations, so this holds whatever the noise's correlation
 * in time; the white-noise formula of least_squares_slope() applied to the residuals of one
 * fit underestimates it when the noise is correlated over the window. DT SE is the
 * statistical (projection-noise) part of the error of a coarse step. Empty when R < 2.
 */
Eigen::VectorXd slope_standard_error(const Eigen::MatrixXd& member_slopes);

/// slope_standard_error(member_least_squares_slopes(t, members, t_start)): the standard error
/// of the slope the fixed-DT integrator projects with; empty when it cannot be measured.
Eigen::VectorXd member_slope_standard_error(std::span<const double> t,
                                            std::span<const Eigen::MatrixXd> members,
                                            double t_start);

}  // namespace efdem::coarse
