#include "mpi_driver/checkpoint_data/realization_state.hpp"

#include <cstring>
#include <type_traits>

#include "core/contracts.hpp"

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
    // Only when set: the checksums of the checkpoints written before it stay valid.
    if (still_samples != 0) h = fnv1a(&still_samples, sizeof still_samples, h);
    return h;
}

namespace {
template <class T>
void put(std::vector<std::uint8_t>& out, const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    out.insert(out.end(), p, p + sizeof v);
}
template <class T>
void put_array(std::vector<std::uint8_t>& out, const std::vector<T>& a) {
    static_assert(std::is_trivially_copyable_v<T>);
    put(out, static_cast<std::uint64_t>(a.size()));
    const auto* p = reinterpret_cast<const std::uint8_t*>(a.data());
    out.insert(out.end(), p, p + a.size() * sizeof(T));
}
struct Reader {
    const std::vector<std::uint8_t>& in;
    std::size_t at = 0;
    template <class T>
    T get() {
        EFDEM_EXPECTS(at + sizeof(T) <= in.size());
        T v;
        std::memcpy(&v, in.data() + at, sizeof v);
        at += sizeof v;
        return v;
    }
    template <class T>
    void get_array(std::vector<T>& a) {
        const auto n = get<std::uint64_t>();
        EFDEM_EXPECTS(at + n * sizeof(T) <= in.size());
        a.resize(n);
        if (n > 0) std::memcpy(a.data(), in.data() + at, n * sizeof(T));
        at += n * sizeof(T);
    }
};
}  // namespace

std::vector<std::uint8_t> pack(const RealizationState& s) {
    std::vector<std::uint8_t> out;
    put(out, s.index);
    put(out, s.time);
    put(out, s.step);
    for (const auto* a : {&s.x, &s.v, &s.omega, &s.force, &s.torque, &s.reference})
        put_array(out, *a);
    put_array(out, s.tag);
    put_array(out, s.species);
    put_array(out, s.pairs);
    for (const auto& w : s.wall) put_array(out, w);
    put(out, s.still_samples);
    return out;
}

RealizationState unpack(const std::vector<std::uint8_t>& bytes) {
    RealizationState s;
    Reader r{bytes};
    s.index = r.get<long>();
    s.time = r.get<double>();
    s.step = r.get<long>();
    for (auto* a : {&s.x, &s.v, &s.omega, &s.force, &s.torque, &s.reference}) r.get_array(*a);
    r.get_array(s.tag);
    r.get_array(s.species);
    r.get_array(s.pairs);
    for (auto& w : s.wall) r.get_array(w);
    s.still_samples = r.get<long>();
    EFDEM_EXPECTS(r.at == bytes.size());
    return s;
}

}  // namespace efdem::mpi_driver
