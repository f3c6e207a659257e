#include "coarse/demixing/rank_windows.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "coarse/demixing/quantiles.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

RankWindows rank_windows(const Eigen::VectorXd& target, const ProbabilityGrid& grid, std::int64_t n,
                         double half_width, double z_low, double z_high) {
    EFDEM_EXPECTS(target.size() == grid.size());
    EFDEM_EXPECTS(n >= 1 && half_width >= 0 && z_low <= z_high);
    const int m = grid.size();
    // Fractional rank of each node and the target's slope per rank there (central; one-sided
    // at the ends; zero with one node).
    std::vector<NodeRank> nodes(static_cast<std::size_t>(m));
    std::vector<double> r(static_cast<std::size_t>(m));
    for (int i = 0; i < m; ++i) {
        const auto ui = static_cast<std::size_t>(i);
        nodes[ui] = node_rank(grid, i, n);
        r[ui] = static_cast<double>(nodes[ui].lower) + nodes[ui].fraction;
    }
    auto slope = [&](int i) {
        const int a = std::max(i - 1, 0), b = std::min(i + 1, m - 1);
        const double dr = r[static_cast<std::size_t>(b)] - r[static_cast<std::size_t>(a)];
        return dr > 0 ? (target[b] - target[a]) / dr : 0.0;
    };
    const auto size = static_cast<std::size_t>(n);
    RankWindows w;
    w.desired.resize(size);
    w.defining.assign(size, 0);
    // Every rank on the target interpolated linearly in rank, extrapolated beyond the ends.
    for (std::size_t k = 0; k < size; ++k) {
        const auto rk = static_cast<double>(k);
        const auto upper = std::upper_bound(r.begin(), r.end(), rk) - r.begin();
        const int i = static_cast<int>(std::clamp<std::ptrdiff_t>(upper, 1, m - 1));
        double z;
        if (m == 1)
            z = target[0];
        else if (upper == 0)
            z = target[0] + (rk - r[0]) * slope(0);
        else if (upper == m)
            z = target[m - 1] + (rk - r[static_cast<std::size_t>(m - 1)]) * slope(m - 1);
        else {
            const double a = r[static_cast<std::size_t>(i - 1)], b = r[static_cast<std::size_t>(i)];
            z = target[i - 1] + (rk - a) / (b - a) * (target[i] - target[i - 1]);
        }
        w.desired[k] = z;
    }
    // The defining ranks about their node: (1 - f) d_lower + f d_lower+1 = target_i exactly.
    for (int i = 0; i < m; ++i) {
        const NodeRank& nr = nodes[static_cast<std::size_t>(i)];
        const auto lo = static_cast<std::size_t>(nr.lower);
        const double g = slope(i);
        w.desired[lo] = target[i] - nr.fraction * g;
        w.defining[lo] = 1;
        if (nr.fraction != 0.0) {
            w.desired[lo + 1] = target[i] + (1 - nr.fraction) * g;
            w.defining[lo + 1] = 1;
        }
    }
    for (std::size_t k = 0; k < size; ++k) {
        w.desired[k] = std::clamp(w.desired[k], z_low, z_high);
        if (k > 0) w.desired[k] = std::max(w.desired[k], w.desired[k - 1]);
    }
    // Windows: a defining rank's own; the others span from the defining rank below to the one
    // above.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    w.low.assign(size, -kInf);
    w.high.assign(size, kInf);
    double below = -kInf;
    for (std::size_t k = 0; k < size; ++k) {
        if (w.defining[k]) below = w.desired[k] - half_width;
        w.low[k] = below;
    }
    double above = kInf;
    for (std::size_t k = size; k-- > 0;) {
        if (w.defining[k]) above = w.desired[k] + half_width;
        w.high[k] = above;
    }
    return w;
}

std::vector<std::int64_t> ranks_kept(std::span<const double> sorted_heights,
                                     const RankWindows& windows) {
    EFDEM_EXPECTS(sorted_heights.size() == windows.desired.size());
    EFDEM_EXPECTS(std::is_sorted(sorted_heights.begin(), sorted_heights.end()));
    const std::size_t n = sorted_heights.size();
    std::vector<std::int64_t> rank(n, -1);
    std::size_t next = 0;
    for (std::size_t j = 0; j < n && next < n; ++j) {
        const double h = sorted_heights[j];
        while (next < n && windows.high[next] < h) ++next;
        if (next < n && windows.low[next] <= h) rank[j] = static_cast<std::int64_t>(next++);
    }
    return rank;
}

}  // namespace efdem::coarse
