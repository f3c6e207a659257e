#pragma once
/// \file
/// Reductions over the members of an ensemble (an R x m matrix, row r = member r): the mean
/// the coarse vector is formed from, and the unbiased variance its statistical error comes
/// from (the spread of the samples, of the members' slopes). Generic: no demixing, no MPI.

#include <Eigen/Core>

namespace efdem::coarse {

/// Column means of an R x m matrix, summed in realization order (so the result does not depend
/// on how the rows were produced). \pre R >= 1.
Eigen::VectorXd ensemble_mean(const Eigen::MatrixXd& rows);
/// Unbiased column variances (divisor R - 1; zeros when R = 1).
Eigen::VectorXd ensemble_variance(const Eigen::MatrixXd& rows, const Eigen::VectorXd& mean);
/// Standard error of the column means, sqrt(variance / R). \pre R >= 2.
Eigen::VectorXd ensemble_standard_error(const Eigen::MatrixXd& rows);

}  // namespace efdem::coarse
