#include "core/rng.hpp"

#include <cmath>
#include <numbers>

#include "core/contracts.hpp"

namespace efdem {

namespace {
/// SplitMix64 finaliser (Steele, Lea & Flood 2014): a bijective 64-bit mixer.
std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}
}  // namespace

RandomStream::RandomStream(std::uint64_t master_seed, std::uint64_t realization,
                           std::string_view purpose) {
    constexpr std::uint64_t golden = 0x9e3779b97f4a7c15ULL;
    // Chain the three key parts through the bijective mixer so that no two keys collide in the
    // 64-bit seed unless the mixer itself collides (it does not: it is a bijection per stage).
    std::uint64_t key = mix64(master_seed + golden);
    key = mix64(key ^ (realization * golden + 0x632be59bd9b4e019ULL));
    key = mix64(key ^ purpose_hash(purpose));
    // Expand the key into the xoshiro state with SplitMix64, as its authors recommend.
    std::uint64_t x = key;
    for (auto& word : s_) {
        x += golden;
        word = mix64(x);
    }
}

double RandomStream::normal() {
    // u1 in (0, 1] so that log(u1) is finite.
    const double u1 = 1.0 - uniform();
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

std::uint64_t RandomStream::below(std::uint64_t n) {
    EFDEM_EXPECTS(n > 0);
    // Lemire's nearly divisionless method on 128-bit products (a GCC/Clang extension).
    __extension__ using u128 = unsigned __int128;
    u128 m = static_cast<u128>(next()) * n;
    auto low = static_cast<std::uint64_t>(m);
    if (low < n) {
        const std::uint64_t threshold = -n % n;
        while (low < threshold) {
            m = static_cast<u128>(next()) * n;
            low = static_cast<std::uint64_t>(m);
        }
    }
    return static_cast<std::uint64_t>(m >> 64);
}

}  // namespace efdem
