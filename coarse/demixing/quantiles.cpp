#include "coarse/demixing/quantiles.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

/// Q(p_i) from a sequence in which at least the order statistics node_rank() names are in
/// their sorted places (a sorted vector, or one prepared by select_order_statistics()).
Eigen::VectorXd evaluate_nodes(std::span<const double> z, const ProbabilityGrid& grid) {
    return quantiles_from_order_statistics(
        static_cast<std::int64_t>(z.size()), grid,
        [&](std::int64_t k) { return z[static_cast<std::size_t>(k)]; });
}

/// Puts the order statistics with the (sorted, unique) ranks `ranks` into their sorted places
/// in v[first, last): nth_element on the middle rank, then each side. O(n log(#ranks)).
void select_order_statistics(std::vector<double>& v, std::span<const std::int64_t> ranks,
                             std::int64_t first, std::int64_t last) {
    if (ranks.empty()) return;
    const std::size_t mid = ranks.size() / 2;
    const std::int64_t rank = ranks[mid];
    std::nth_element(v.begin() + first, v.begin() + rank, v.begin() + last);
    select_order_statistics(v, ranks.first(mid), first, rank);
    select_order_statistics(v, ranks.subspan(mid + 1), rank + 1, last);
}

[[maybe_unused]] bool all_finite(std::span<const double> z) {
    return std::all_of(z.begin(), z.end(), [](double v) { return std::isfinite(v); });
}

}  // namespace

NodeRank node_rank(const ProbabilityGrid& grid, int i, std::int64_t n) {
    EFDEM_EXPECTS(n >= 1);
    // r = (2 (i+1) n - (m+1)) / (2 (m+1)), exact in 64-bit integers for any realistic n.
    const std::int64_t num = 2 * grid.numerator(i) * n - grid.denominator();
    const std::int64_t den = 2 * grid.denominator();
    if (num <= 0) return {0, 0.0};
    const std::int64_t lower = num / den;
    if (lower >= n - 1) return {n - 1, 0.0};
    return {lower, static_cast<double>(num % den) / static_cast<double>(den)};
}

Eigen::VectorXd quantiles_from_order_statistics(
    std::int64_t n, const ProbabilityGrid& grid,
    const std::function<double(std::int64_t)>& order_statistic) {
    EFDEM_EXPECTS(n >= 1);
    Eigen::VectorXd q(grid.size());
    for (int i = 0; i < grid.size(); ++i) {
        const NodeRank r = node_rank(grid, i, n);
        const double lower = order_statistic(r.lower);
        q[i] =
            r.fraction == 0.0 ? lower : lower + r.fraction * (order_statistic(r.lower + 1) - lower);
    }
    return q;
}

double quantile_sorted(std::span<const double> sorted, double p) {
    EFDEM_EXPECTS(!sorted.empty());
    EFDEM_EXPECTS(p >= 0.0 && p <= 1.0);
    const auto n = static_cast<double>(sorted.size());
    const double r = p * n - 0.5;
    if (r <= 0.0) return sorted.front();
    if (r >= n - 1.0) return sorted.back();
    const double lower = std::floor(r);
    const auto k = static_cast<std::size_t>(lower);
    return sorted[k] + (r - lower) * (sorted[k + 1] - sorted[k]);
}

Eigen::VectorXd quantiles_sorted(std::span<const double> sorted, const ProbabilityGrid& grid) {
    EFDEM_EXPECTS(!sorted.empty());
    EFDEM_EXPECTS(std::is_sorted(sorted.begin(), sorted.end()));
    EFDEM_EXPECTS(all_finite(sorted));
    return evaluate_nodes(sorted, grid);
}

Eigen::VectorXd quantiles(std::span<const double> heights, const ProbabilityGrid& grid) {
    EFDEM_EXPECTS(!heights.empty());
    EFDEM_EXPECTS(all_finite(heights));
    const auto n = static_cast<std::int64_t>(heights.size());
    std::vector<std::int64_t> ranks;
    ranks.reserve(2 * static_cast<std::size_t>(grid.size()));
    for (int i = 0; i < grid.size(); ++i) {
        const NodeRank r = node_rank(grid, i, n);
        ranks.push_back(r.lower);
        if (r.fraction != 0.0) ranks.push_back(r.lower + 1);
    }
    std::sort(ranks.begin(), ranks.end());
    ranks.erase(std::unique(ranks.begin(), ranks.end()), ranks.end());
    std::vector<double> z(heights.begin(), heights.end());
    select_order_statistics(z, ranks, 0, n);
    return evaluate_nodes(z, grid);
}

std::int64_t count_below_quantile(const ProbabilityGrid& grid, int i, std::int64_t n) {
    EFDEM_EXPECTS(n >= 1);
    EFDEM_EXPECTS(i >= 0 && i < grid.size());
    const std::int64_t num = 2 * grid.numerator(i) * n - grid.denominator();
    const std::int64_t den = 2 * grid.denominator();
    const std::int64_t ceil_r = num <= 0 ? 0 : (num + den - 1) / den;
    return std::min(ceil_r, n - 1);
}

}  // namespace efdem::coarse
