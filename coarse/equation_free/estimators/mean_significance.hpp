#pragma once
/// \file
/// Whether the realizations' mean of a vector quantity stands above their own scatter: the test
/// behind "a decay rate resolved above the noise" (projective/stability_monitor.hpp) and "a
/// transient after the lift" (post_lift_transient.hpp).
///
/// Given R independent realizations' values v_{r,i} (i = 1..n components), the ensemble mean
/// m_i and its squared standard error se_i^2 = Var_r(v_{r,i})/R, the statistic is the ratio of
/// sums
///
///     S = sum_i m_i^2 / sum_i se_i^2,
///
/// ~1 when the true mean is zero. The ratio of sums, not the mean of the ratios m_i^2/se_i^2:
/// each ratio alone is F(1, R - 1)-distributed, whose mean is 3 at R = 4 and whose variance is
/// infinite below R = 6, while the pooled denominator has n (R - 1) degrees of freedom. For
/// noise alone Var(S) ~ 2 (1 + 1/(R - 1)) / n_eff with n_eff = (sum se^2)^2 / sum se^4 (the
/// number of components that carry the variance); the mean counts as resolved when S exceeds
/// 1 + 3 sqrt(2 (1 + 1/(R - 1)) / n_eff), three standard deviations.

#include <limits>

#include <Eigen/Core>

namespace efdem::coarse {

struct MeanSignificance {
    bool measured = false;  ///< false: fewer than 2 realizations or no component
    bool resolved = false;  ///< S > threshold
    double statistic = std::numeric_limits<double>::quiet_NaN();  ///< S
    double threshold = std::numeric_limits<double>::quiet_NaN();
};

/// The test above on `values` (R x n, row r = realization r). Realizations without any scatter
/// (every se = 0): resolved exactly when some mean is not zero.
MeanSignificance mean_significance(const Eigen::MatrixXd& values);

/// The same test on an estimate `mean` (n components) whose noise variance per component
/// `se2` was measured from the scatter of `realizations` realizations (a linear combination of
/// their means, e.g. a divided difference of slopes). Not measured with fewer than 2
/// realizations or no component. \pre mean.size() == se2.size(), se2 >= 0.
MeanSignificance significance(const Eigen::VectorXd& mean, const Eigen::VectorXd& se2,
                              int realizations);

}  // namespace efdem::coarse
