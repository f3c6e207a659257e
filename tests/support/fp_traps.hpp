#pragma once
// Floating-point exception traps for tests (glibc feenableexcept).
#include <cfenv>

namespace efdem::test {
inline void enable_fp_traps() {
    feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
}
inline void disable_fp_traps() {
    fedisableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
}

/// Turns traps off for a scope (for a test that deliberately produces a NaN).
class FpTrapsOff {
  public:
    FpTrapsOff() : saved_(fegetexcept()) { disable_fp_traps(); }
    ~FpTrapsOff() {
        std::feclearexcept(FE_ALL_EXCEPT);
        feenableexcept(saved_);
    }
    FpTrapsOff(const FpTrapsOff&) = delete;
    FpTrapsOff& operator=(const FpTrapsOff&) = delete;

  private:
    int saved_;
};
}  // namespace efdem::test
