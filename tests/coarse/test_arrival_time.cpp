// arrival_time (the time to the end state of cpi.hand_off = steady,
// coarse/equation_free/estimators/arrival_time.hpp).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

#include "coarse/equation_free/estimators/arrival_time.hpp"

using namespace efdem::coarse;

TEST_CASE("arrival_time finds when a relaxing trajectory came within the radius for good",
          "[unit][arrival]") {
    // x(t) = e^{-t/10} v with |v| = 5, sampled every 2 units: |x| <= 0.5 from t = 10 ln 10 =
    // 23.03 on, so the first sample inside is t = 24 (exact arithmetic; no tolerance needed).
    const Eigen::VectorXd v = Eigen::VectorXd::Constant(4, 2.5);  // |v| = 5
    std::vector<double> t;
    std::vector<Eigen::VectorXd> x;
    for (int k = 0; k <= 30; ++k) {
        t.push_back(2.0 * k);
        x.push_back(std::exp(-t.back() / 10.0) * v);
    }
    const Eigen::VectorXd target = Eigen::VectorXd::Zero(4);
    CHECK(arrival_time(t, x, target, 0.5) == 24.0);
    // An excursion beyond the radius later on: arrival is after it.
    x[20] = v;  // t = 40
    CHECK(arrival_time(t, x, target, 0.5) == 42.0);
    // Still outside at the end: never arrived.
    x.back() = v;
    CHECK(std::isnan(arrival_time(t, x, target, 0.5)));
    // A state of another size (the coarse variable changed) counts as outside.
    x.back() = Eigen::VectorXd::Zero(3);
    CHECK(std::isnan(arrival_time(t, x, target, 0.5)));
    // Nothing recorded: NaN.
    CHECK(std::isnan(arrival_time({}, {}, target, 1.0)));
    // Every state within: the first time.
    CHECK(arrival_time(t, std::vector<Eigen::VectorXd>(t.size(), target), target, 0.0) == 0.0);
}
