#pragma once
// Measured figures of a test (stability margins, energies, timings of nothing): printed only when
// EFDEM_REPORT is set, as scripts/run_slow_tests.sh does, so that docs/stability.md can quote
// them; silent in the default tier.
#include <cstdio>
#include <cstdlib>
#include <string>

namespace efdem::test {
inline void report(const std::string& line) {
    if (std::getenv("EFDEM_REPORT")) std::printf("[figure] %s\n", line.c_str());
}
}  // namespace efdem::test
