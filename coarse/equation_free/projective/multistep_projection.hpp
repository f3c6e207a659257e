#pragma once
/// \file
/// The projection of a multistep coarse integrator and its two error parts, from the slopes
/// the bursts measured (docs/error_control.md derives every formula here).
///
/// A burst's least-squares slope s_k estimates dX/dt at the centre tau_k of its window, with a
/// standard error se_k per component (the spread of the realizations' own slopes / sqrt(R)).
/// A q-step method models dX/dt over the jump by the polynomial P of degree q - 1 through the
/// last q slopes (q = 1: projective forward Euler, P = s_n; q = 2: projective Adams-Bashforth 2,
/// the line through s_{n-1} and s_n) and projects
///
///     X(t0 + DT) = X(t0) + integral_{t0}^{t0+DT} P(t) dt = X(t0) + sum_k W_k s_k.
///
/// * Statistical error: the slopes' noise carried by the weights, per component
///   sqrt(sum_k W_k^2 se_k^2) — whatever the noise's correlation in time, since se_k is measured
///   from independent realizations.
/// * Truncation error: dX/dt - P(t) = D omega(t) + ..., with omega(t) = prod_k (t - tau_k) over
///   the method's nodes and D the q-th divided difference of dX/dt; the error of the jump is
///   D integral_{t0}^{t0+DT} omega(t) dt. D is measured from q + 1 slopes (before the jump: the
///   last q + 1 accepted ones; after it: the method's q plus the slope of the burst that follows
///   the jump), with its noise removed from its norm (an unbiased estimate of |D|^2).
///
/// Norms are root-mean-square over the components (for the ICDF: over the p-grid, in d_p).
/// Times in sqrt(d_p/g).

#include <span>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/estimators/pooled_curvature.hpp"
#include "coarse/equation_free/estimators/slope_node.hpp"

namespace efdem::coarse {

/**
 * \brief W_k = integral_{t0}^{t0+dt} L_k(t) dt for the Lagrange basis L_k of `nodes`' tau.
 *
 * One node: W = {dt}. Exact (3-point Gauss-Legendre) for up to three nodes.
 * \pre 1 <= nodes.size() <= 3, distinct taus, dt >= 0.
 */
std::vector<double> projection_weights(std::span<const SlopeNode> nodes, double t0, double dt);

/// sum_k W_k s_k: the increment of X over the jump. \pre weights.size() == nodes.size().
Eigen::VectorXd projected_increment(std::span<const SlopeNode> nodes,
                                    std::span<const double> weights);

/// Per component sqrt(sum_k W_k^2 se_k^2): the projection noise of the jump.
Eigen::VectorXd statistical_error(std::span<const SlopeNode> nodes,
                                  std::span<const double> weights);

/// | integral_{t0}^{t0+dt} prod_k (t - tau_k) dt | over the method's nodes.
double omega_integral(std::span<const SlopeNode> nodes, double t0, double dt);

/// The q-th divided difference of the slopes over q + 1 nodes.
struct DividedDifference {
    Eigen::VectorXd value;           ///< per component
    Eigen::VectorXd noise_variance;  ///< its variance from the nodes' standard errors
    /// sqrt(max(0, mean(value^2) - mean(noise_variance))): the RMS of the part that is not
    /// noise (unbiased for |D|^2 when the slopes' errors are independent).
    double norm = 0.0;
};

/// \pre nodes.size() >= 2, distinct taus, slopes and se of one size.
DividedDifference slope_divided_difference(std::span<const SlopeNode> nodes);

/// What a pooled curvature b (cpi.curvature = pooled) leaves of the divided difference of
/// `nodes`' slopes: d - b per component, its noise variance Var(d) + Var(b) - 2 Cov(d, b) (the
/// nodes b was fitted to, matched by tau, share their noise with it) and its debiased norm.
/// \pre as slope_divided_difference; b of the nodes' size.
DividedDifference curvature_left(std::span<const SlopeNode> nodes, const PooledCurvature& b);

/// RMS over the components.
double rms(const Eigen::VectorXd& v);

/// sqrt(max(0, mean(value^2) - mean(noise_variance))): the RMS of the part of an estimate that
/// is not noise (unbiased for |value|^2 when its components' errors are independent); 0 for no
/// component. DividedDifference::norm, and cpi.noisy_curvature = pooled's charge.
double debiased_rms(const Eigen::VectorXd& value, const Eigen::VectorXd& noise_variance);

}  // namespace efdem::coarse
