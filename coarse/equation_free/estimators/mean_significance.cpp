#include "coarse/equation_free/estimators/mean_significance.hpp"

#include <cmath>

#include "core/contracts.hpp"

namespace efdem::coarse {

MeanSignificance mean_significance(const Eigen::MatrixXd& values) {
    const Eigen::Index r = values.rows();
    if (r < 2 || values.cols() < 1) return {};
    const Eigen::RowVectorXd mean = values.colwise().mean();
    // se_i^2 = unbiased Var_r / R.
    const Eigen::RowVectorXd se2 = (values.rowwise() - mean).colwise().squaredNorm() /
                                   (static_cast<double>(r - 1) * static_cast<double>(r));
    return significance(mean.transpose(), se2.transpose(), static_cast<int>(r));
}

MeanSignificance significance(const Eigen::VectorXd& mean, const Eigen::VectorXd& se2,
                              int realizations) {
    EFDEM_EXPECTS(mean.size() == se2.size());
    MeanSignificance s;
    if (realizations < 2 || mean.size() < 1) return s;
    s.measured = true;
    const double num = mean.squaredNorm(), den = se2.sum();
    if (den == 0.0) {
        s.resolved = num > 0.0;
        s.statistic = num > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
        s.threshold = 0.0;
        return s;
    }
    const double n_eff = den * den / se2.squaredNorm();
    const double nu = static_cast<double>(realizations - 1);
    s.statistic = num / den;
    s.threshold = 1.0 + 3.0 * std::sqrt(2.0 * (1.0 + 1.0 / nu) / n_eff);
    s.resolved = s.statistic > s.threshold;
    return s;
}

}  // namespace efdem::coarse
