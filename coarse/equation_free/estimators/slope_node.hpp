#pragma once
/// \file
/// SlopeNode: one measured coarse slope — where it belongs in time, its value and its standard
/// error. A burst's least-squares slope is one (multistep_projection.hpp projects from them);
/// SlopePool (slope_pool.hpp) combines several into one. Times in sqrt(d_p/g).

#include <Eigen/Core>

namespace efdem::coarse {

struct SlopeNode {
    double tau = 0.0;       ///< centre of the estimation window
    Eigen::VectorXd slope;  ///< s [unit of X per sqrt(d_p/g)]
    Eigen::VectorXd se;     ///< standard error of s per component (same unit)
};

}  // namespace efdem::coarse
