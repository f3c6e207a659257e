#include "coarse/demixing/whole_bed_profile.hpp"

#include <algorithm>
#include <cmath>

#include "coarse/demixing/quantiles.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {
[[maybe_unused]] bool is_profile(const Eigen::VectorXd& profile) {
    if (profile.size() != kWholeBedNodes || !profile.allFinite()) return false;
    for (Eigen::Index k = 1; k < profile.size(); ++k)
        if (profile[k] < profile[k - 1]) return false;
    return true;
}
}  // namespace

ProbabilityGrid whole_bed_interior_grid() {
    return ProbabilityGrid(static_cast<int>(kWholeBedNodes) - 2);
}

Eigen::VectorXd profile_of_heights(std::vector<double> heights) {
    EFDEM_EXPECTS(!heights.empty());
    std::sort(heights.begin(), heights.end());
    Eigen::VectorXd out(kWholeBedNodes);
    out[0] = heights.front();
    out.segment(1, kWholeBedNodes - 2) = quantiles_sorted(heights, whole_bed_interior_grid());
    out[kWholeBedNodes - 1] = heights.back();
    return out;
}

Eigen::VectorXd whole_bed_ranks() {
    Eigen::VectorXd u(kWholeBedNodes);
    const ProbabilityGrid grid = whole_bed_interior_grid();
    u[0] = 0.0;
    for (int i = 0; i < grid.size(); ++i) u[i + 1] = grid.p(i);
    u[kWholeBedNodes - 1] = 1.0;
    return u;
}

Eigen::VectorXd ranks_in(const Eigen::VectorXd& heights, const Eigen::VectorXd& profile) {
    EFDEM_EXPECTS(is_profile(profile));
    const Eigen::VectorXd u = whole_bed_ranks();
    const double* begin = profile.data();
    const double* end = begin + profile.size();
    Eigen::VectorXd out(heights.size());
    for (Eigen::Index i = 0; i < heights.size(); ++i) {
        const double z = heights[i];
        if (std::isnan(z)) {
            out[i] = z;
            continue;
        }
        // The nodes at z form the stretch [lo, hi) (empty when z falls between two nodes).
        const auto lo = std::lower_bound(begin, end, z) - begin;
        const auto hi = std::upper_bound(begin, end, z) - begin;
        if (hi > lo) {  // z is a node (or several equal ones): the middle of their ranks
            out[i] = 0.5 * (u[lo] + u[hi - 1]);
        } else if (lo == 0) {
            out[i] = 0.0;
        } else if (lo == profile.size()) {
            out[i] = 1.0;
        } else {  // profile[lo - 1] < z < profile[lo]
            const double f = (z - profile[lo - 1]) / (profile[lo] - profile[lo - 1]);
            out[i] = u[lo - 1] + f * (u[lo] - u[lo - 1]);
        }
    }
    return out;
}

Eigen::VectorXd heights_at(const Eigen::VectorXd& ranks, const Eigen::VectorXd& profile) {
    EFDEM_EXPECTS(is_profile(profile));
    const Eigen::VectorXd u = whole_bed_ranks();
    const Eigen::Index last = kWholeBedNodes - 1;
    Eigen::VectorXd out(ranks.size());
    for (Eigen::Index i = 0; i < ranks.size(); ++i) {
        if (std::isnan(ranks[i])) {
            out[i] = ranks[i];
            continue;
        }
        const double r = std::clamp(ranks[i], 0.0, 1.0);
        // The interval [u_k, u_k+1] that holds r (the last one for r = 1).
        const auto k = std::min<Eigen::Index>(
            std::upper_bound(u.data(), u.data() + u.size(), r) - u.data() - 1, last - 1);
        const double f = (r - u[k]) / (u[k + 1] - u[k]);
        out[i] = profile[k] + f * (profile[k + 1] - profile[k]);
    }
    return out;
}

}  // namespace efdem::coarse
