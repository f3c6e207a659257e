#include "coarse/equation_free/ensemble_statistics.hpp"

#include "core/contracts.hpp"

namespace efdem::coarse {

Eigen::VectorXd ensemble_mean(const Eigen::MatrixXd& rows) {
    EFDEM_EXPECTS(rows.rows() >= 1);
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(rows.cols());
    for (Eigen::Index r = 0; r < rows.rows(); ++r) sum += rows.row(r).transpose();
    return sum / static_cast<double>(rows.rows());
}

Eigen::VectorXd ensemble_variance(const Eigen::MatrixXd& rows, const Eigen::VectorXd& mean) {
    Eigen::VectorXd var = Eigen::VectorXd::Zero(rows.cols());
    if (rows.rows() < 2) return var;
    for (Eigen::Index r = 0; r < rows.rows(); ++r)
        var += (rows.row(r).transpose() - mean).cwiseAbs2();
    return var / static_cast<double>(rows.rows() - 1);
}

Eigen::VectorXd ensemble_standard_error(const Eigen::MatrixXd& rows) {
    EFDEM_EXPECTS(rows.rows() >= 2);
    return (ensemble_variance(rows, ensemble_mean(rows)) / static_cast<double>(rows.rows()))
        .cwiseSqrt();
}

}  // namespace efdem::coarse
