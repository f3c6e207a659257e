#pragma once
/// \file
/// SlopePool: a slope estimate from the last few bursts instead of one (cpi.slope = pooled), and
/// the bookkeeping that tells the error budget how much of each burst's noise earlier jumps have
/// already put into the state (docs/error_control.md §7 derives every formula here).
///
/// Every accepted burst k measures a slope y_k = s(tau_k) + eta_k with independent noise eta_k
/// of standard error se_k per component (the members' spread). The pooled estimate over the last
/// m bursts is the weighted mean
///
///     s_pool = sum_k w_k y_k,   w_k = (1/v_k) / sum_j (1/v_j),   v_k = mean_i se_{k,i}^2,
///
/// one weight per burst (the same for every component, so that the estimate is exact for a slope
/// linear in time at ONE time, tau_pool = sum_k w_k tau_k, the node's tau: the truncation model
/// of a forward-Euler jump from that node covers the lag). Its noise per component is
/// se_pool = sqrt(sum_k w_k^2 se_k^2), down to se/sqrt(m) for m bursts of equal noise.
///
/// The catch is that pooled jumps reuse bursts: the errors of successive jumps are correlated,
/// and what a jump adds to the state's error is not its own variance. A jump of DT from s_pool
/// puts DT w_k eta_k of every pooled burst's noise into the state; after the jumps so far, burst
/// k's noise sits there with the coefficient a_k (its "commitment", sum over the jumps that used
/// it of DT w_k). A jump raises a_k to a_k + DT w_k, so the variance of the state's accumulated
/// error grows by
///
///     Delta V_i = sum_k [(a_k + DT w_k)^2 - a_k^2] se_{k,i}^2
///               = DT^2 se_pool,i^2 + 2 DT c_i,   c_i = sum_k w_k a_k se_{k,i}^2,
///
/// and sqrt(Delta V) is the statistical part the budget charges (one burst, never reused:
/// a = 0, Delta V = DT^2 se^2, the classic DT se). With equal DT and noise, a full pool of m
/// equal weights charges exactly DT se per jump again: over a long run the sum of the pooled
/// slopes telescopes to the sum of the bursts' own, so pooling cannot lower the accumulated
/// error at equal DT — it lowers each jump's own scatter, and it uses bursts no jump has used
/// (direct bursts, the warm-up's last window) at full value.

#include <cstddef>
#include <deque>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/estimators/slope_node.hpp"

namespace efdem::coarse {

/// Where a jump's slope comes from (cpi.slope).
enum class SlopeSource {
    burst,   ///< the last burst's own least-squares slope
    pooled,  ///< SlopePool: the weighted mean of the last bursts' slopes
};
/// "burst" or "pooled": the key's values and the text recorded in the run file.
std::string_view to_string(SlopeSource source);

/// One burst in the pool: its measured slope and how much of its noise is in the state.
struct PooledBurst {
    SlopeNode node;
    double commitment = 0.0;  ///< a_k = sum over kept jumps that used it of DT w_k [time]
};

/// A pooled slope: the node to project from and the weights that made it.
struct PooledSlope {
    SlopeNode node;               ///< tau_pool, s_pool, se_pool
    std::vector<double> weights;  ///< w_k of the last bursts used, oldest first (sum 1)
    Eigen::VectorXd committed;    ///< c_i = sum_k w_k a_k se_{k,i}^2 [unit^2 per time]
    std::size_t bursts() const { return weights.size(); }
};

/// Per component sqrt(Delta V) = sqrt(dt^2 se^2 + 2 dt c) of a jump of `dt` from a slope of
/// standard error `se` whose noise has the covariance `committed` (c, per unit dt) with the
/// noise already in the state (see the file comment): the growth of the accumulated error's
/// variance, as a standard deviation. \pre dt >= 0; se and committed of one size.
Eigen::VectorXd charged_error(const Eigen::VectorXd& se, const Eigen::VectorXd& committed,
                              double dt);

class SlopePool {
  public:
    /// \pre capacity >= 1: the most bursts one estimate may pool (cpi.pool).
    explicit SlopePool(std::size_t capacity);

    /// A new accepted burst (no jump has used it yet); the oldest falls out beyond capacity.
    /// \pre node.slope and node.se of the size of the bursts already in the pool.
    void add(const SlopeNode& node);
    /// The estimate over the last `m` bursts. \pre 1 <= m <= size().
    PooledSlope estimate(std::size_t m) const;
    /// A jump of `dt` from `e` was kept: every burst it used gets a_k += dt w_k.
    /// \pre e was made by estimate() of this pool, with no add() since.
    void commit(const PooledSlope& e, double dt);
    /// A kept jump put `scale` x `weights[k]` of the last weights.size() bursts' noise into the
    /// state: a_k += scale w_k, oldest first (commit; a pooled curvature's omega c_k,
    /// pooled_curvature.hpp). \pre weights.size() <= size().
    void add_commitments(std::span<const double> weights, double scale);

    std::size_t size() const { return bursts_.size(); }
    std::size_t capacity() const { return capacity_; }
    /// The pooled bursts, oldest first (saved in a checkpoint).
    const std::deque<PooledBurst>& bursts() const { return bursts_; }
    /// \pre bursts.size() <= capacity().
    void restore(std::deque<PooledBurst> bursts);

  private:
    std::size_t capacity_;
    std::deque<PooledBurst> bursts_;
};

}  // namespace efdem::coarse
