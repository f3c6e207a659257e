// The Catch2 runner for serial test executables (unit, physics, regression tiers).
// Kept in its own object file: catch.hpp's runner is slow to compile.
//
// Floating-point exceptions (invalid, divide-by-zero, overflow) are trapped for the whole run:
// a NaN or an Inf produced anywhere in a kernel stops the test where it appears (as libgran's
// tests do) instead of propagating silently into a comparison.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include "tests/support/fp_traps.hpp"

int main(int argc, char* argv[]) {
    efdem::test::enable_fp_traps();
    return Catch::Session().run(argc, argv);
}
