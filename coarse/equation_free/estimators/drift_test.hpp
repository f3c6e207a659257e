#pragma once
/// \file
/// DriftTest: has a moving ensemble reached a statistically steady state? (cpi.finish = steady
/// for a bed that never comes to rest, docs/error_control.md §1.)
///
/// It pools the slopes of the last k accepted bursts the way SlopePool does (one inverse-variance
/// weight per burst, w_j = (1/v_j) / sum 1/v, v_j = mean_i se_j,i^2):
///
///     s_i = sum_j w_j s_j,i,   se_i = sqrt(sum_j w_j^2 se_j,i^2),   z = RMS_i (s_i / se_i).
///
/// Each burst's se is the members' spread of their own slopes (R - 1 degrees of freedom), and the
/// members' slope deviations of successive bursts are uncorrelated (lag-1 correlation 0.00-0.15,
/// pooling four windows leaves 0.25-0.30 of the variance: bench/results/slope_noise §2), so with
/// no drift each s_i / se_i is close to a standard normal (a Student t of about k (R - 1) degrees
/// of freedom) and z is about 1, whatever the burst length and however correlated the members'
/// levels are in time. A drift d adds about d / se to each: z grows with the pool. The state is
/// called steady when z <= kSteadyZ (2: a drift the pool cannot tell from zero at the 5 % level
/// even if all nodes told the same story) at `confirmations` checks in a row, each after a new
/// accepted burst. Measured (bench/results/steady_detection.md, "Pooled slopes"): with k = 4 bursts
/// of 10 units, 1.0-1.4 in a steady fluidized bed (U_s = 0.41, R = 4), 3.6-5.9 through a slow
/// demixing (U_s = 0.19, R = 4 and 8). Generic: no MPI, no DEM.

#include <cstddef>
#include <deque>
#include <vector>

#include "coarse/equation_free/estimators/slope_node.hpp"

namespace efdem::coarse {

class DriftTest {
  public:
    /// The largest z called steady.
    static constexpr double kSteadyZ = 2.0;
    /// A noiseless component's pooled slope at or below this (in X's units per unit time) did
    /// not move: round-off of slopes that are 0 (1e-26 seen) is far below it, a real drift far
    /// above (1e-4 d_p per time unit moves a node by 0.01 d_p in 100 units).
    static constexpr double kExactlyQuiet = 1e-12;

    /// \pre bursts >= 2 (one burst's slope is the controller's own; a pool is what tells a
    /// drift from noise); confirmations >= 1.
    DriftTest(std::size_t bursts, int confirmations);

    /// A new accepted burst's slope; the oldest falls out beyond `bursts`. A node without a
    /// finite slope and standard error (e.g. from one realization) empties the pool: nothing can
    /// be judged across it. A component whose se is 0 in every pooled burst (the members moved
    /// alike: a segregated bed in rank coordinates) counts as quiet when its pooled slope is 0 (|s|
    /// <= kExactlyQuiet) and as an exactly known drift (z infinite) when not. \pre
    /// node.slope.size() == node.se.size().
    void add(const SlopeNode& node);
    /// Forget everything (the ensemble changed, or a realization came to rest).
    void clear();

    /// Whether the pool is full.
    bool ready() const { return nodes_.size() == bursts_; }
    /// z of the full pool (NaN unless ready()).
    double z() const;
    /// ready() and z() <= kSteadyZ at the last `confirmations` checks in a row.
    bool steady() const { return ready() && quiet_ >= confirmations_; }
    /// The centre of the oldest pooled burst's window (NaN when empty): the state has been
    /// steady since about then.
    double since() const;

    /// The pool and the count of quiet checks, for checkpoints: flat doubles, restorable by
    /// restore() with the same number of components. Empty when the pool is.
    std::vector<double> save() const;
    void restore(const std::vector<double>& state);

  private:
    std::size_t bursts_;
    int confirmations_;
    std::deque<SlopeNode> nodes_;
    int quiet_ = 0;  ///< consecutive checks with z <= kSteadyZ, up to the last add()
};

}  // namespace efdem::coarse
