// Random streams: reproducible per (seed, realization, purpose), independent across keys.
#include <catch2/catch.hpp>

#include <cmath>
#include <numeric>
#include <vector>

#include "core/rng.hpp"

using efdem::RandomStream;

TEST_CASE("a stream is reproducible from its key and from its saved state", "[unit][rng]") {
    RandomStream a(7, 3, "lifting"), b(7, 3, "lifting");
    for (int i = 0; i < 1000; ++i) REQUIRE(a.next() == b.next());
    const auto saved = a.state();
    std::vector<double> first;
    for (int i = 0; i < 100; ++i) first.push_back(a.normal());
    RandomStream c(saved);
    for (int i = 0; i < 100; ++i) REQUIRE(c.normal() == first[static_cast<std::size_t>(i)]);
}

TEST_CASE("the first draws of a stream are pinned (portable across standard libraries)",
          "[unit][rng][regression]") {
    // Recorded from this implementation (xoshiro256** seeded by SplitMix64 of the key hash) on
    // 2026-11-23. Integer draws are pure integer arithmetic, so they are the same on any
    // platform. If this test changes, every seeded result of efdem changes: bump the checkpoint
    // format version.
    RandomStream s(1, 0, "packing");
    CHECK(s.next() == 0x519fe7e8997c8836ULL);
    CHECK(s.next() == 0xe70ecd1e4a14e10bULL);
    CHECK(s.next() == 0x377b587b8de0d3faULL);
    // normal() goes through log/cos; glibc's are correctly rounded in practice, so a tight
    // relative tolerance suffices.
    CHECK(s.normal() == Approx(-0.018802784249117226).epsilon(1e-14));
}

TEST_CASE("streams of different purposes, realizations or seeds are uncorrelated", "[unit][rng]") {
    // For n independent uniforms the sample correlation has standard deviation 1/sqrt(n);
    // 5 sigma (0.025 for n = 40000) is a bound a correct generator fails with p ~ 6e-7.
    const int n = 40000;
    auto correlation = [n](RandomStream a, RandomStream b) {
        double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
        for (int i = 0; i < n; ++i) {
            const double x = a.uniform(), y = b.uniform();
            sa += x;
            sb += y;
            saa += x * x;
            sbb += y * y;
            sab += x * y;
        }
        const double cov = sab / n - (sa / n) * (sb / n);
        return cov / std::sqrt((saa / n - sa * sa / n / n) * (sbb / n - sb * sb / n / n));
    };
    const double bound = 5.0 / std::sqrt(static_cast<double>(n));
    CHECK(std::abs(correlation({1, 0, "lifting"}, {1, 0, "velocities"})) < bound);
    CHECK(std::abs(correlation({1, 0, "lifting"}, {1, 1, "lifting"})) < bound);
    CHECK(std::abs(correlation({1, 0, "lifting"}, {2, 0, "lifting"})) < bound);
    CHECK(std::abs(correlation({0, 1, "lifting"}, {1, 0, "lifting"})) < bound);
}

TEST_CASE("drawing from one stream never shifts another", "[unit][rng]") {
    RandomStream dem(5, 2, "velocities"), dem_ref(5, 2, "velocities");
    RandomStream lift(5, 2, "lifting");
    for (int i = 0; i < 10; ++i) lift.next();  // lifting draws in between ...
    for (int i = 0; i < 100; ++i) REQUIRE(dem.next() == dem_ref.next());  // ... change nothing
}

TEST_CASE("uniform, below and normal have the right distributions", "[unit][rng]") {
    RandomStream s(11, 0, "test");
    const int n = 200000;
    // uniform: mean 1/2, variance 1/12; tolerance 5 standard errors.
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const double u = s.uniform();
        REQUIRE(u >= 0.0);
        REQUIRE(u < 1.0);
        sum += u;
        sum2 += u * u;
    }
    CHECK(std::abs(sum / n - 0.5) < 5 * std::sqrt(1.0 / 12 / n));
    CHECK(std::abs(sum2 / n - sum * sum / n / n - 1.0 / 12) < 1e-3);
    // below(7): chi-square with 6 degrees of freedom; 30 is beyond the 99.99 % quantile (27.9).
    std::vector<int> counts(7, 0);
    for (int i = 0; i < n; ++i) ++counts[s.below(7)];
    double chi2 = 0;
    for (int c : counts) chi2 += (c - n / 7.0) * (c - n / 7.0) / (n / 7.0);
    CHECK(chi2 < 30.0);
    // normal: mean 0 and variance 1 within 5 standard errors (variance s.e. = sqrt(2/n)).
    double m = 0, v = 0;
    for (int i = 0; i < n; ++i) {
        const double z = s.normal();
        m += z;
        v += z * z;
    }
    m /= n;
    v = v / n - m * m;
    CHECK(std::abs(m) < 5 / std::sqrt(n));
    CHECK(std::abs(v - 1) < 5 * std::sqrt(2.0 / n));
}

TEST_CASE("shuffle is a permutation and is reproducible", "[unit][rng]") {
    std::vector<int> a(100), b(100);
    std::iota(a.begin(), a.end(), 0);
    b = a;
    RandomStream s1(3, 4, "packing"), s2(3, 4, "packing");
    s1.shuffle(a.begin(), a.end());
    s2.shuffle(b.begin(), b.end());
    CHECK(a == b);
    std::vector<int> sorted = a;
    std::sort(sorted.begin(), sorted.end());
    for (int i = 0; i < 100; ++i) REQUIRE(sorted[static_cast<std::size_t>(i)] == i);
    CHECK(a != sorted);
}
