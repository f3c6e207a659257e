// Probability grid, empirical quantile function (physics.md §8) and monotone repair (§9 step 1).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "coarse/demixing/monotone_repair.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "coarse/demixing/quantiles.hpp"
#include "core/rng.hpp"

using namespace efdem::coarse;

namespace {
std::vector<double> uniform_heights(efdem::RandomStream& rng, std::size_t n, double h = 50.0) {
    std::vector<double> z(n);
    for (double& v : z) v = rng.uniform(0.0, h);
    return z;
}
}  // namespace

TEST_CASE("the default probability grid is p = 0.05 i, i = 1..19", "[unit][coarse]") {
    const ProbabilityGrid grid;
    REQUIRE(grid.size() == 19);
    // (i+1)/20 is one correctly rounded division: within 1 ulp of the decimal value.
    for (int i = 0; i < 19; ++i) CHECK(grid.p(i) == Approx(0.05 * (i + 1)).epsilon(1e-15));
    CHECK(grid.edge(0) == 0.0);
    CHECK(grid.edge(20) == 1.0);
    CHECK(grid.edge(5) == grid.p(4));
    CHECK(ProbabilityGrid(3).values().isApprox(Eigen::Vector3d(0.25, 0.5, 0.75)));
}

TEST_CASE("quantile function matches hand-computed values", "[unit][coarse]") {
    // Sorted {1,2,3,4}: Q interpolates through (0.125,1) (0.375,2) (0.625,3) (0.875,4). All
    // values below are exact in binary, so the comparisons are exact.
    const std::vector<double> z{1, 2, 3, 4};
    CHECK(quantile_sorted(z, 0.5) == 2.5);
    CHECK(quantile_sorted(z, 0.25) == 1.5);
    CHECK(quantile_sorted(z, 0.0) == 1.0);     // constant below the first point
    CHECK(quantile_sorted(z, 0.125) == 1.0);   // on the first point
    CHECK(quantile_sorted(z, 0.9375) == 4.0);  // constant above the last point
    CHECK(quantile_sorted(z, 1.0) == 4.0);
    const ProbabilityGrid quarters(3);
    const std::vector<double> unsorted{3, 1, 4, 2};
    CHECK(quantiles(unsorted, quarters) == Eigen::Vector3d(1.5, 2.5, 3.5));
    CHECK(quantiles_sorted(z, quarters) == Eigen::Vector3d(1.5, 2.5, 3.5));

    SECTION("with ties") {
        // {1,2,2,5}: points (0.125,1) (0.375,2) (0.625,2) (0.875,5).
        const std::vector<double> t{2, 5, 1, 2};
        CHECK(quantiles(t, quarters) == Eigen::Vector3d(1.5, 2.0, 3.5));
    }
    SECTION("n = 1 is a constant") {
        const std::vector<double> one{7.25};
        CHECK(quantiles(one, ProbabilityGrid()) == Eigen::VectorXd::Constant(19, 7.25));
        CHECK(quantile_sorted(one, 0.3) == 7.25);
    }
    SECTION("n = 10 on the default grid: nodes land on and between points") {
        // r_i = 0.05 (i+1) 10 - 1/2 = (i+1)/2 - 1/2: z = 0..9 gives Q(p_i) = i/2 exactly.
        std::vector<double> ten(10);
        for (int k = 0; k < 10; ++k) ten[static_cast<std::size_t>(k)] = 9 - k;
        const Eigen::VectorXd q = quantiles(ten, ProbabilityGrid());
        for (int i = 0; i < 19; ++i) CHECK(q[i] == 0.5 * i);
    }
}

TEST_CASE("selection-based quantiles equal the sorted ones exactly, any n", "[unit][coarse]") {
    efdem::RandomStream rng(3, 0, "test-quantiles");
    for (std::size_t n : {1u, 2u, 3u, 7u, 19u, 20u, 21u, 100u, 1001u, 20000u}) {
        for (int m : {1, 4, 19, 99}) {
            const ProbabilityGrid grid(m);
            const auto z = uniform_heights(rng, n);
            auto sorted = z;
            std::sort(sorted.begin(), sorted.end());
            const Eigen::VectorXd a = quantiles(z, grid), b = quantiles_sorted(sorted, grid);
            // The same order statistics enter the same formula: bitwise equality.
            REQUIRE(a == b);
            for (int i = 0; i < m; ++i)
                CHECK(quantile_sorted(sorted, grid.p(i)) == Approx(b[i]).epsilon(1e-12));
        }
    }
}

TEST_CASE("count_below_quantile counts the distinct points strictly below Q(p_i)",
          "[unit][coarse]") {
    // Every n from 1 to 60 covers nodes below the first point, on points (exact half ranks),
    // between points and above the last point; the count is an integer fact, no tolerance.
    efdem::RandomStream rng(4, 0, "test-quantiles");
    for (int m : {3, 19}) {
        const ProbabilityGrid grid(m);
        for (std::int64_t n = 1; n <= 60; ++n) {
            auto z = uniform_heights(rng, static_cast<std::size_t>(n));
            std::sort(z.begin(), z.end());
            const Eigen::VectorXd q = quantiles_sorted(z, grid);
            for (int i = 0; i < m; ++i) {
                const auto below =
                    std::count_if(z.begin(), z.end(), [&](double v) { return v < q[i]; });
                REQUIRE(count_below_quantile(grid, i, n) == below);
            }
        }
    }
}

TEST_CASE("isotonic regression: hand examples and the projection conditions", "[unit][coarse]") {
    Eigen::VectorXd x(4);
    x << 1, 3, 2, 4;
    isotonic_regression(x);
    CHECK(x == Eigen::Vector4d(1, 2.5, 2.5, 4));
    Eigen::VectorXd y(6);
    y << 1, 4, 2, 3, 0, 5;  // pools (4,2,3,0) into their mean 9/4
    isotonic_regression(y);
    Eigen::VectorXd expected(6);
    expected << 1, 2.25, 2.25, 2.25, 2.25, 5;
    CHECK(y == expected);

    // The isotonic regression is characterised by S_i = sum_{j<=i} (x_j - y_j) >= 0 for every i,
    // with S_i = 0 where y steps up and at the end (Barlow et al. 1972). Checked on random input
    // to round-off (1e-12 of the data scale, sums of <= 200 terms of size <= 1).
    efdem::RandomStream rng(5, 0, "test-pav");
    for (int trial = 0; trial < 200; ++trial) {
        const auto m = static_cast<Eigen::Index>(1 + rng.below(200));
        Eigen::VectorXd in(m);
        for (Eigen::Index i = 0; i < m; ++i) in[i] = rng.uniform() + 0.01 * static_cast<double>(i);
        Eigen::VectorXd out = in;
        isotonic_regression(out);
        double s = 0.0;
        for (Eigen::Index i = 0; i < m; ++i) {
            s += in[i] - out[i];
            REQUIRE(s >= -1e-12);
            if (i + 1 < m) {
                REQUIRE(out[i + 1] >= out[i]);
                if (out[i + 1] > out[i]) REQUIRE(std::abs(s) <= 1e-12);
            }
        }
        REQUIRE(std::abs(s) <= 1e-12);
    }
}

TEST_CASE("monotone repair leaves a valid target untouched and reports what it changes",
          "[unit][coarse]") {
    SECTION("monotone and inside the range: bit-for-bit unchanged, empty report") {
        Eigen::VectorXd x(5);
        x << 0.5, 1.0, 1.0, 7.5, 40.0;
        const Eigen::VectorXd before = x;
        const RepairReport r = repair_monotone(x, 0.5, 48.0);
        CHECK(x == before);
        CHECK(r.feasible);
        CHECK_FALSE(r.non_monotone);
        CHECK_FALSE(r.changed());
        CHECK(r.n_clipped == 0);
        CHECK(r.message.empty());
    }
    SECTION("non-monotone: pooled, and the largest change reported") {
        Eigen::VectorXd x(3);
        x << 3, 2, 1;
        const RepairReport r = repair_monotone(x, 0.0, 10.0);
        CHECK(x == Eigen::Vector3d(2, 2, 2));
        CHECK(r.non_monotone);
        CHECK(r.max_adjustment == 1.0);
        CHECK_THAT(r.message, Catch::Contains("isotonic"));
    }
    SECTION("outside the feasible range: clipped and counted") {
        Eigen::VectorXd x(3);
        x << -1, 2, 10;
        const RepairReport r = repair_monotone(x, 0.0, 5.0);
        CHECK(x == Eigen::Vector3d(0, 2, 5));
        CHECK(r.n_clipped == 2);
        CHECK(r.max_adjustment == 5.0);
        CHECK_FALSE(r.non_monotone);
        CHECK_THAT(r.message, Catch::Contains("2 node(s) clipped"));
    }
    SECTION("non-finite: infeasible, untouched, the node named") {
        Eigen::VectorXd x(3);
        x << 1, std::numeric_limits<double>::quiet_NaN(), 2;
        const RepairReport r = repair_monotone(x, 0.0, 5.0);
        CHECK_FALSE(r.feasible);
        CHECK(x[0] == 1.0);
        CHECK(std::isnan(x[1]));
        CHECK_THAT(r.message, Catch::Contains("node 1"));
    }
}
