#include "mpi_driver/checkpoint/realization_state.hpp"

namespace efdem::mpi_driver {

std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t h) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < bytes; ++k) {
        h ^= p[k];
        h *= 0x100000001b3ULL;
    }
    return h;
}

std::uint64_t RealizationState::checksum() const {
    std::uint64_t h = fnv1a(&index, sizeof index);
    h = fnv1a(&time, sizeof time, h);
    h = fnv1a(&step, sizeof step, h);
    for (const auto* a : {&x, &v, &omega, &force, &torque, &reference}) h = fnv1a_array(*a, h);
    h = fnv1a_array(tag, h);
    h = fnv1a_array(species, h);
    for (const auto& p : pairs) {
        h = fnv1a(&p.tag_i, sizeof p.tag_i, h);
        h = fnv1a(&p.tag_j, sizeof p.tag_j, h);
        h = fnv1a(&p.xi, sizeof p.xi, h);
    }
    for (const auto& w : wall) h = fnv1a_array(w, h);
    return h;
}

}  // namespace efdem::mpi_driver
