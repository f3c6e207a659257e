#pragma once
/// \file
/// The evenly spaced probability grid on which ICDFs are sampled (physics.md §8, Q10).

#include <cstdint>

#include <Eigen/Core>

namespace efdem::coarse {

/**
 * \brief Evenly spaced probability nodes p_i = (i + 1)/(m + 1), i = 0..m-1 (0-based, as the
 *        entries of the coarse vector).
 *
 * The coarse vector of a species ICDF is X_i = Q(p_i) (physics.md §8). The default m = 19 gives
 * p = 0.05, 0.10, ..., 0.95: evenly spaced, excluding the noisy extremes p = 0 and p = 1 (Q10).
 * Lifting cuts [0, 1] into the m + 1 cells [edge(k), edge(k+1)], k = 0..m, with edge(0) = 0,
 * edge(i + 1) = p_i and edge(m + 1) = 1 (physics.md §9 step 2).
 *
 * The nodes are the exact rationals numerator(i)/denominator(); quantile positions are computed
 * from them in integer arithmetic (quantiles.hpp), so a node that falls exactly on a sample point
 * is evaluated exactly, with no rounding deciding which side of it the node lies.
 *
 * \code
 * ProbabilityGrid grid;        // m = 19
 * grid.p(0);                   // 0.05
 * grid.p(18);                  // 0.95
 * ProbabilityGrid coarse(3);   // p = 0.25, 0.5, 0.75
 * \endcode
 */
class ProbabilityGrid {
  public:
    /// \pre m >= 1.
    explicit ProbabilityGrid(int m = 19);

    /// Number of nodes m.
    int size() const { return m_; }
    /// p_i = (i + 1)/(m + 1). \pre 0 <= i < m.
    double p(int i) const;
    /// Cell edge k/(m + 1), k = 0..m+1 (edge(0) = 0, edge(i + 1) = p(i), edge(m + 1) = 1).
    double edge(int k) const;
    /// All nodes (p_0, ..., p_{m-1}).
    Eigen::VectorXd values() const;

    /// p_i = numerator(i)/denominator(), exactly.
    std::int64_t numerator(int i) const { return i + 1; }
    std::int64_t denominator() const { return m_ + 1; }

    friend bool operator==(const ProbabilityGrid&, const ProbabilityGrid&) = default;

  private:
    int m_;
};

}  // namespace efdem::coarse
