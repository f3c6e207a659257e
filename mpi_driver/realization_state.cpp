#include "mpi_driver/realization_state.hpp"

namespace efdem::mpi_driver {

std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t h) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) {
        h ^= p[k];
        h *= 0x100000001b3ULL;
    }
    return h;
}

namespace {
template <class T>
std::uint64_t hash_array(const std::vector<T>& a, std::uint64_t h) {
    const std::uint64_t n = a.size();
    h = fnv1a(&n, sizeof n, h);
    return a.empty() ? h : fnv1a(a.data(), a.size() * sizeof(T), h);
}
}  // namespace

std::uint64_t RealizationState::checksum() const {
    std::uint64_t h = fnv1a(&index, sizeof index);
    h = fnv1a(&time, sizeof time, h);
    h = fnv1a(&step, sizeof step, h);
    for (const auto* a : {&x, &v, &omega, &force, &torque, &reference}) h = hash_array(*a, h);
    h = hash_array(tag, h);
    h = hash_array(species, h);
    for (const auto& p : pairs) {
        h = fnv1a(&p.tag_i, sizeof p.tag_i, h);
        h = fnv1a(&p.tag_j, sizeof p.tag_j, h);
        h = fnv1a(&p.xi, sizeof p.xi, h);
    }
    for (const auto& w : wall) h = hash_array(w, h);
    return h;
}

}  // namespace efdem::mpi_driver
