// The default tiers run with floating-point traps on (tests/catch_main.cpp): a NaN or Inf made
// anywhere in a kernel stops the test where it appears. This proves the traps are really on,
// and that FpTrapsOff (for tests that make a NaN on purpose) turns them off only in its scope.
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cfenv>
#include <cmath>
#include <csignal>
#include <cstdlib>

#include "tests/support/fp_traps.hpp"

namespace {
// volatile: the compiler must not fold the divisions at compile time.
volatile double zero = 0.0;
volatile double huge = 1e308;
}  // namespace

TEST_CASE("FP traps are on for invalid, divide-by-zero and overflow in the test runner",
          "[unit][fp]") {
    const int enabled = fegetexcept();
    CHECK((enabled & FE_INVALID) == FE_INVALID);
    CHECK((enabled & FE_DIVBYZERO) == FE_DIVBYZERO);
    CHECK((enabled & FE_OVERFLOW) == FE_OVERFLOW);
}

TEST_CASE("a 0/0 with the traps on stops the process with SIGFPE", "[unit][fp]") {
    // In a child process, so that the trap does not end this test run.
    const pid_t child = fork();
    REQUIRE(child >= 0);
    if (child == 0) {
        // The default action (Catch2 and AddressSanitizer install their own SIGFPE handlers).
        std::signal(SIGFPE, SIG_DFL);
        const double nan = zero / zero;
        std::_Exit(std::isnan(nan) ? 0 : 1);  // reached only if nothing trapped
    }
    int status = 0;
    REQUIRE(waitpid(child, &status, 0) == child);
    CHECK(WIFSIGNALED(status));
    CHECK(WTERMSIG(status) == SIGFPE);
}

TEST_CASE("FpTrapsOff lets 0/0, 1/0 and overflow through, raises the flags, and restores the traps",
          "[unit][fp]") {
    {
        efdem::test::FpTrapsOff off;
        CHECK(fegetexcept() == 0);
        std::feclearexcept(FE_ALL_EXCEPT);
        const double nan = zero / zero;  // would be SIGFPE with the traps on
        CHECK(std::isnan(nan));
        CHECK(std::fetestexcept(FE_INVALID));
        const double inf = 1.0 / zero;
        CHECK(std::isinf(inf));
        CHECK(std::fetestexcept(FE_DIVBYZERO));
        const double over = huge * 10.0;
        CHECK(std::isinf(over));
        CHECK(std::fetestexcept(FE_OVERFLOW));
    }
    // Back in the normal scope: the three traps again, and no stale flag left behind.
    CHECK((fegetexcept() & (FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW)) ==
          (FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW));
    CHECK_FALSE(std::fetestexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW));
}
