// DriftTest (cpi.finish = steady for a moving ensemble): calibrated on noise of known variance,
// its power against a drift, and its state (coarse/equation_free/estimators/drift_test.hpp).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>

#include "coarse/equation_free/estimators/drift_test.hpp"

using namespace efdem::coarse;

namespace {
/// A burst's slope node: slope = drift + noise of standard error `se` (independent per
/// component, or one common draw for all when `common`).
SlopeNode node(std::mt19937_64& rng, double tau, int m, double drift, double se, bool common) {
    std::normal_distribution<double> normal;
    SlopeNode n;
    n.tau = tau;
    n.se = Eigen::VectorXd::Constant(m, se);
    const double shared = normal(rng);
    n.slope.resize(m);
    for (int i = 0; i < m; ++i) n.slope[i] = drift + se * (common ? shared : normal(rng));
    return n;
}
}  // namespace

TEST_CASE("the drift test's z is 1 on average without drift and grows with a drift",
          "[unit][coarse]") {
    std::mt19937_64 rng(3);
    // No drift, 19 independent nodes, se varying from burst to burst (the weights must not bias
    // it): E[z^2] = 1 exactly for a pool of normal slopes with their true se. 4,000 pools give
    // mean z^2 to +-1.5 % (s.d. of z^2 = sqrt(2/19) over sqrt(4000)); 5 % allows 3 s.d.
    double sum = 0;
    int above = 0;
    const int trials = 4000;
    for (int t = 0; t < trials; ++t) {
        DriftTest d(4, 1);
        for (int b = 0; b < 4; ++b) d.add(node(rng, 10.0 * b, 19, 0.0, 0.01 * (1 + b % 2), false));
        REQUIRE(d.ready());
        sum += d.z() * d.z();
        above += d.z() > DriftTest::kSteadyZ;
    }
    CHECK(sum / trials == Approx(1.0).epsilon(0.05));
    CHECK(above == 0);  // chi^2_19 / 19 > 4 has probability 2e-9
    // Nodes that all tell the same story (fully correlated): z = |N(0,1)|, above 2 with
    // probability 4.6 %; at two checks in a row (pools overlapping in 3 of 4 bursts) fewer pass
    // as steady wrongly than that. Here the opposite error is counted: a steady state missed.
    int steady = 0;
    for (int t = 0; t < trials; ++t) {
        DriftTest d(4, 2);
        for (int b = 0; b < 5; ++b) d.add(node(rng, 10.0 * b, 19, 0.0, 0.01, true));
        steady += d.steady();
    }
    // P(|N| <= 2 at both checks) >= 1 - 2 x 0.046 = 0.91.
    CHECK(static_cast<double>(steady) / trials > 0.88);
    // A drift of 2 se per burst: pooled over 4 bursts z ~ 4, never steady at 2 checks.
    int wrongly = 0;
    for (int t = 0; t < 1000; ++t) {
        DriftTest d(4, 2);
        for (int b = 0; b < 5; ++b) d.add(node(rng, 10.0 * b, 19, 0.02, 0.01, false));
        wrongly += d.steady();
    }
    CHECK(wrongly == 0);
}

TEST_CASE("the drift test needs a full pool and quiet checks in a row; it keeps its state",
          "[unit][coarse]") {
    std::mt19937_64 rng(5);
    DriftTest d(3, 2);
    CHECK(std::isnan(d.z()));
    CHECK(std::isnan(d.since()));
    SlopeNode quiet;
    quiet.slope = Eigen::VectorXd::Zero(4);
    quiet.se = Eigen::VectorXd::Constant(4, 0.1);
    for (int b = 0; b < 3; ++b) {
        CHECK_FALSE(d.steady());
        quiet.tau = 5.0 + 10.0 * b;
        d.add(quiet);
    }
    CHECK(d.z() == 0.0);
    CHECK_FALSE(d.steady());  // one quiet check so far
    const std::vector<double> saved = d.save();
    quiet.tau = 35.0;
    d.add(quiet);
    CHECK(d.steady());
    CHECK(d.since() == 15.0);  // the oldest burst of the pool
    // Restored from the state saved before the last burst: the same answer after it.
    DriftTest again(3, 2);
    again.restore(saved);
    CHECK(again.save() == saved);
    again.add(quiet);
    CHECK(again.steady());
    CHECK(again.save() == d.save());
    // A loud burst resets the count; a burst without a standard error (one member) empties the
    // pool: nothing is judged across it.
    SlopeNode loud = quiet;
    loud.slope.setConstant(1.0);
    d.add(loud);
    CHECK_FALSE(d.steady());
    SlopeNode blind = quiet;
    blind.se.setConstant(std::numeric_limits<double>::quiet_NaN());
    d.add(blind);
    CHECK_FALSE(d.ready());
    CHECK(d.save().empty());
}

TEST_CASE("a component without noise is quiet when it does not move and a drift when it does",
          "[unit][coarse]") {
    // A segregated bed in rank coordinates: every member's lowest light node sits at the same
    // rank, so its slope and its standard error are exactly 0 in every burst. It must neither
    // block the test (0/0) nor count as noise; the other components decide.
    DriftTest d(2, 1);
    SlopeNode n;
    n.slope = Eigen::Vector3d(0.0, 0.01, -0.01);
    n.se = Eigen::Vector3d(0.0, 0.1, 0.1);
    n.tau = 1.0;
    d.add(n);
    n.tau = 2.0;
    d.add(n);
    REQUIRE(d.ready());
    CHECK(d.z() == Approx(0.01 / (0.1 / std::sqrt(2.0))));  // the two noisy components only
    CHECK(d.steady());
    // The same component moving with every member alike: an exactly known drift.
    n.slope[0] = 1e-3;
    d.add(n);
    CHECK(std::isinf(d.z()));
    CHECK_FALSE(d.steady());
    // Nothing noisy and nothing moving: z = 0.
    DriftTest still(2, 1);
    SlopeNode zero;
    zero.slope = Eigen::Vector2d::Zero();
    zero.se = Eigen::Vector2d::Zero();
    still.add(zero);
    still.add(zero);
    CHECK(still.z() == 0.0);
    CHECK(still.steady());
}
