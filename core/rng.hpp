#pragma once
/// \file
/// Reproducible random streams, one per (master seed, realization index, purpose).
///
/// Why: results must not depend on how realizations are spread over ranks, and drawing lifting
/// random numbers must never shift the DEM's own draws. So every consumer owns a stream keyed by
/// what it is for ("packing", "velocities", "lifting", ...) and by the *global* realization index;
/// no stream is shared and none depends on the rank.
///
/// Generator: xoshiro256** (Blackman & Vigna 2018), state seeded by SplitMix64 from a hash of the
/// key. Distributions are implemented here, not taken from <random>, whose normal and uniform-int
/// distributions are implementation-defined: the same seed gives the same numbers with any
/// standard library, which bit-exact restarts and cross-machine comparisons rely on.

#include <array>
#include <cstdint>
#include <string_view>
#include <utility>

namespace efdem {

/// FNV-1a hash of a purpose name; constexpr so that purposes can be compile-time constants.
constexpr std::uint64_t purpose_hash(std::string_view purpose) {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    for (char c : purpose) {
        h ^= static_cast<unsigned char>(c);
        h *= 0x100000001b3ULL;
    }
    return h;
}

/**
 * \brief A random stream for one purpose of one realization.
 *
 * \code
 * RandomStream lifting(seed, realization, "lifting");
 * double u = lifting.uniform();          // [0, 1)
 * std::uint64_t k = lifting.below(10);   // 0..9, unbiased
 * auto saved = lifting.state();          // checkpoint ...
 * lifting.set_state(saved);              // ... and restore exactly
 * \endcode
 */
class RandomStream {
  public:
    using State = std::array<std::uint64_t, 4>;

    RandomStream(std::uint64_t master_seed, std::uint64_t realization, std::string_view purpose);
    explicit RandomStream(const State& state) : s_(state) {}

    /// 64 random bits.
    std::uint64_t next() {
        const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
        const std::uint64_t t = s_[1] << 17;
        s_[2] ^= s_[0];
        s_[3] ^= s_[1];
        s_[1] ^= s_[2];
        s_[0] ^= s_[3];
        s_[2] ^= t;
        s_[3] = rotl(s_[3], 45);
        return result;
    }
    /// Uniform in [0, 1) with 53 random bits.
    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
    /// Uniform in [a, b).
    double uniform(double a, double b) { return a + (b - a) * uniform(); }
    /// Standard normal (Box-Muller; two uniforms per call, no cached second value, so the state
    /// is the whole story).
    double normal();
    /// Uniform integer in [0, n), n > 0, without modulo bias (Lemire 2019).
    std::uint64_t below(std::uint64_t n);

    /// Fisher-Yates shuffle of [first, last) with this stream.
    template <class RandomIt>
    void shuffle(RandomIt first, RandomIt last) {
        const auto n = static_cast<std::uint64_t>(last - first);
        for (std::uint64_t i = n; i > 1; --i) {
            const std::uint64_t j = below(i);
            using std::swap;
            swap(first[i - 1], first[j]);
        }
    }

    const State& state() const { return s_; }
    void set_state(const State& s) { s_ = s; }

  private:
    static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
    State s_{};
};

}  // namespace efdem
