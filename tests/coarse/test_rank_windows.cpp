// Rank windows (coarse/demixing/rank_windows.hpp): the heights each order statistic should
// have, the windows that bound every node's error, and the largest order-preserving set of
// particles that may stay.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "coarse/demixing/quantiles.hpp"
#include "coarse/demixing/rank_windows.hpp"
#include "core/rng.hpp"

using namespace efdem;
using namespace efdem::coarse;

namespace {

const ProbabilityGrid kGrid;  // m = 19

/// A demixed-looking target: heights 1..11 d_p, steep at both ends, flat in the middle.
Eigen::VectorXd smooth_target() {
    Eigen::VectorXd t(kGrid.size());
    for (int i = 0; i < kGrid.size(); ++i) {
        const double p = kGrid.p(i);
        t[i] = 6.0 + 5.0 * std::tan(2.4 * (p - 0.5)) / std::tan(1.2);
    }
    return t;
}

/// The most particles an order-preserving assignment to ranks can keep (dynamic programme over
/// particles and ranks, the longest common subsequence's recursion).
long most_kept(const std::vector<double>& sorted, const RankWindows& w) {
    const std::size_t n = sorted.size();
    std::vector<std::vector<long>> best(n + 1, std::vector<long>(n + 1, 0));
    for (std::size_t j = 1; j <= n; ++j)
        for (std::size_t r = 1; r <= n; ++r) {
            const bool fits = w.low[r - 1] <= sorted[j - 1] && sorted[j - 1] <= w.high[r - 1];
            best[j][r] =
                std::max({best[j - 1][r], best[j][r - 1], fits ? best[j - 1][r - 1] + 1 : 0L});
        }
    return best[n][n];
}

}  // namespace

TEST_CASE("heights at their ranks' desired values reproduce the target ICDF",
          "[lifting][rank_windows]") {
    // n >= 2 (m + 1) = 40: no two nodes share a defining rank (rank_windows.hpp).
    const std::int64_t n = GENERATE(100, 40, 800);
    CAPTURE(n);
    const Eigen::VectorXd target = smooth_target();
    const RankWindows w = rank_windows(target, kGrid, n, 0.1, 0.0, 20.0);
    REQUIRE(std::is_sorted(w.desired.begin(), w.desired.end()));
    const Eigen::VectorXd q = quantiles_sorted(w.desired, kGrid);
    // The defining ranks straddle each node with its local slope: exact to rounding.
    CHECK((q - target).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("any heights inside their windows put every node within the half-width",
          "[lifting][rank_windows]") {
    const std::int64_t n = GENERATE(100, 40);
    const double half_width = GENERATE(0.05, 0.3);
    CAPTURE(n, half_width);
    const Eigen::VectorXd target = smooth_target();
    const RankWindows w = rank_windows(target, kGrid, n, half_width, 0.0, 20.0);
    RandomStream rng(3, 0, "test-rank-windows");
    double worst = 0;
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<double> z(static_cast<std::size_t>(n));
        for (std::size_t k = 0; k < z.size(); ++k) {
            // Unbounded tails drawn within 3 d_p of the desired height.
            const double lo = std::max(w.low[k], w.desired[k] - 3.0);
            const double hi = std::min(w.high[k], w.desired[k] + 3.0);
            z[k] = rng.uniform(lo, hi);
        }
        const Eigen::VectorXd q = quantiles(z, kGrid);
        worst = std::max(worst, (q - target).cwiseAbs().maxCoeff());
    }
    // The guarantee of rank_windows.hpp (1e-12: rounding); the draws use most of it.
    CHECK(worst <= half_width + 1e-12);
    CHECK(worst > 0.5 * half_width);
}

TEST_CASE("the greedy keeps as many particles as any order-preserving assignment",
          "[lifting][rank_windows]") {
    RandomStream rng(9, 0, "test-rank-windows");
    ProbabilityGrid grid(4);
    for (int trial = 0; trial < 300; ++trial) {
        const std::int64_t n = 3 + static_cast<std::int64_t>(rng.below(10));
        Eigen::VectorXd target(grid.size());
        for (int i = 0; i < grid.size(); ++i) target[i] = rng.uniform(0.0, 4.0);
        std::sort(target.begin(), target.end());
        const RankWindows w = rank_windows(target, grid, n, rng.uniform(0.0, 0.5), 0.0, 4.0);
        std::vector<double> z(static_cast<std::size_t>(n));
        for (double& h : z) h = rng.uniform(-0.5, 4.5);
        std::sort(z.begin(), z.end());
        const std::vector<std::int64_t> kept = ranks_kept(z, w);
        long count = 0;
        std::int64_t last = -1;
        for (std::size_t j = 0; j < z.size(); ++j) {
            if (kept[j] < 0) continue;
            ++count;
            const auto r = static_cast<std::size_t>(kept[j]);
            CHECK(kept[j] > last);  // order kept
            CHECK(w.low[r] <= z[j]);
            CHECK(z[j] <= w.high[r]);
            last = kept[j];
        }
        INFO("trial " << trial);
        CHECK(count == most_kept(z, w));
    }
}

TEST_CASE("rank heights are clipped into the bed and stay ordered", "[lifting][rank_windows]") {
    Eigen::VectorXd target = smooth_target();
    // The floor: no centre of the observed spheres below 1 d_p, the top at 10.
    const RankWindows w = rank_windows(target, kGrid, 100, 0.1, 1.0, 10.0);
    CHECK(*std::min_element(w.desired.begin(), w.desired.end()) >= 1.0);
    CHECK(*std::max_element(w.desired.begin(), w.desired.end()) <= 10.0);
    CHECK(std::is_sorted(w.desired.begin(), w.desired.end()));
    CHECK(std::is_sorted(w.low.begin(), w.low.end()));
    CHECK(std::is_sorted(w.high.begin(), w.high.end()));
    // Two defining ranks per node at n = 100 (p_i n - 1/2 is never a whole number).
    CHECK(std::count(w.defining.begin(), w.defining.end(), 1) == 2 * kGrid.size());
}
