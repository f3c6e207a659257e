#pragma once
/// \file
/// The curvature of the slow path pooled over the slopes of several bursts (cpi.curvature =
/// pooled; docs/error_control.md §3, "A curvature pooled over the bursts").
///
/// Each accepted burst k measured the slope s_k at the centre tau_k of its window, with a
/// standard error se_k per component from the realizations' spread. Per component the
/// least-squares line s(t) = a + b (t - tau_mean) through them gives the curvature
///
///     b = sum_k c_k s_k,   c_k = (tau_k - tau_mean) / sum_j (tau_j - tau_mean)^2,
///
/// whose noise, the slopes' errors being independent (their windows do not overlap), has the
/// variance sum_k c_k^2 se_k^2 and with each slope s_k the covariance c_k se_k^2 (the last
/// slope is the one a forward-Euler jump also uses). The weights are equal, not 1/se_k^2: the
/// bursts' se_k are estimates (R - 1 degrees of freedom each), and weights drawn from them add
/// noise the formula does not count (with 8 realizations the corrected jumps' RMS error was 2.8 %
/// above their own variance as computed with them, 1.6 % without); the
/// bursts of one run have similar se_k anyway.
///
/// What a jump that adds omega b charges: it puts g_k eta_k of every pooled burst's noise into the
/// state, g_k = DT [k newest] + omega c_k, where earlier jumps put a_k eta_k (the pool's
/// commitments, slope_pool.hpp). The accumulated error's variance grows by
/// sum_k [(a_k + g_k)^2 - a_k^2] se_k^2: the jump's own variance (DT^2 se^2 + omega^2 Var(b) +
/// 2 DT omega Cov(b, s_last)) plus 2 omega kappa, kappa = sum_k a_k c_k se_k^2 (`committed`).
/// The older bursts, already used, have c_k < 0, so b takes back part of the noise their jumps
/// put in: charging each jump's own variance alone overcharged the run's accumulated error.
///
/// One burst's halves resolve a curvature only where it changes the slope by more than one
/// burst's noise within the burst; bursts a jump apart see DT times more of it. On the tall bed
/// at U_s = 0.19 every forward-Euler jump undershot the accelerating demixing by less than its
/// own noise, all by the same sign (docs/accuracy_vs_cost.md, the tall bed against two directs).
///
/// \code
/// const PooledCurvature b = pooled_curvature(last_bursts);  // >= 2 nodes, distinct taus
/// x += dt * s_last + omega * b.value;                        // omega: forward Euler's integral
/// \endcode

#include <span>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/estimators/slope_node.hpp"

namespace efdem::coarse {

struct PooledCurvature {
    Eigen::VectorXd value;     ///< b per component [unit per time^2]
    Eigen::VectorXd variance;  ///< Var(b) per component
    /// Cov(b, s_k): row k for node k (oldest first), one column per component.
    Eigen::MatrixXd cov_slopes;
    std::vector<double> tau;      ///< the nodes' tau_k, oldest first
    std::vector<double> weights;  ///< c_k, oldest first (b = sum_k c_k s_k; they sum to 0)
    /// kappa = sum_k a_k Cov(b, s_k) per component, a_k the coefficient with which burst k's
    /// slope noise is already in the state (its commitment, slope_pool.hpp): the covariance of
    /// b's noise with the error earlier jumps made. Empty: none (counted 0).
    Eigen::VectorXd committed;
    bool empty() const { return value.size() == 0; }
    std::size_t bursts() const { return static_cast<std::size_t>(cov_slopes.rows()); }
    /// Cov(b, s_last), the newest node's slope (positive: the newest lies after tau_mean).
    Eigen::VectorXd cov_last() const { return cov_slopes.row(cov_slopes.rows() - 1).transpose(); }
};

/// The fit above over `nodes` (oldest first). \pre nodes.size() >= 2, distinct taus, slopes
/// and se of one size, se >= 0.
PooledCurvature pooled_curvature(std::span<const SlopeNode> nodes);

/// kappa above (PooledCurvature::committed) for the commitments a_k of b's nodes, oldest first.
/// \pre commitments.size() == b.bursts().
Eigen::VectorXd committed_covariance(const PooledCurvature& b, std::span<const double> commitments);

}  // namespace efdem::coarse
