#pragma once
/// \file
/// Run-time choice of an AVX2 build of a hot kernel inside the default (portable) build.
///
/// A kernel that wants it is written once, marked `[[gnu::always_inline]]`, and called from
/// two wrappers: a plain one and one marked EFDEM_TARGET_AVX2, which the compiler builds with
/// AVX2 encodings (three-operand VEX instructions: far fewer register copies and spills in
/// Vec3 arithmetic). `cpu_has_avx2()` picks the wrapper at run time, so the binary still runs
/// on any x86-64.
///
/// The AVX2 target deliberately excludes FMA: without fused multiply-adds the compiler cannot
/// contract a*b + c, every operation rounds as in the baseline build, and results are the same
/// to the bit whichever wrapper runs. (A build for the host CPU, EFDEM_NATIVE, may contract.)
///
/// Where the compiler already targets AVX2, or is not GCC/Clang on x86-64, there is one build
/// and cpu_has_avx2() is false.

namespace efdem {

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(__AVX2__)
#define EFDEM_AVX2_DISPATCH 1
#define EFDEM_TARGET_AVX2 __attribute__((target("avx2")))
inline bool cpu_has_avx2() {
    static const bool has = __builtin_cpu_supports("avx2");
    return has;
}
#else
#define EFDEM_AVX2_DISPATCH 0
#define EFDEM_TARGET_AVX2
inline bool cpu_has_avx2() {
    return false;
}
#endif

}  // namespace efdem
