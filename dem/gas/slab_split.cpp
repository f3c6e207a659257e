#include "dem/gas/slab_split.hpp"

#include <algorithm>
#include <cmath>

#include "core/cpu_dispatch.hpp"
#include "dem/gas/slab_fields.hpp"

namespace efdem::dem {

namespace {
[[gnu::always_inline]] inline SlabSplit split(std::size_t n, const Vec3* __restrict x,
                                              const double* __restrict rad, double dz,
                                              double max_slabs, std::uint32_t* __restrict first,
                                              std::uint8_t* __restrict count,
                                              double* __restrict w) {
    const double inv_dz = 1.0 / dz;
    std::uint32_t top = 1;
    int out_of_range = 0;  // an int, not a bool: the compiler vectorizes the |= of an int
    for (std::size_t i = 0; i < n; ++i) {
        // An out-of-range or NaN position is computed as z = 0 (no conversion of it) and
        // reported; the comparison is quiet here (-fno-trapping-math lets the compiler pick it).
        const double t_top = (x[i].z + rad[i]) * inv_dz;
        const bool in_range = std::abs(t_top) < max_slabs;
        out_of_range |= in_range ? 0 : 1;
        const double z = in_range ? x[i].z : 0.0, r = in_range ? rad[i] : 0.5 * dz;
        // Slab k holds [k dz, (k+1) dz): the sphere [z - r, z + r] touches slabs lo..hi with
        // lo = max(0, floor((z - r)/dz)) (whatever lies below z = 0 belongs to slab 0) and
        // hi = ceil((z + r)/dz) - 1 (a top exactly on a plane does not reach the slab above).
        // Integer truncation computes both (floor/ceil are slow without SSE4.1): for the
        // non-negative values that matter trunc = floor, and clamping handles the rest.
        const double t_hi = (z + r) * inv_dz;
        const double t_lo = std::max((z - r) * inv_dz, 0.0);
        const auto top_trunc = static_cast<std::int32_t>(t_hi);
        const std::int32_t hi = top_trunc - (static_cast<double>(top_trunc) == t_hi ? 1 : 0);
        const auto lo = static_cast<std::int32_t>(t_lo);
        const bool two = hi > lo;
        const auto j0 = static_cast<std::uint32_t>(lo);
        first[i] = j0;
        count[i] = two ? 2 : 1;
        top = std::max(top, j0 + (two ? 2u : 1u));
        // Exact partial volumes: the cap below the one interior plane, kept within the whole
        // sphere against round-off so that no weight is negative.
        const double full = sphere_volume_below(z + r, z, r);
        const double g =
            std::min(sphere_volume_below(static_cast<double>(j0 + 1) * dz, z, r), full);
        w[2 * i] = two ? g : full;
        w[2 * i + 1] = two ? full - g : 0.0;
    }
    return {top, out_of_range != 0};
}

EFDEM_TARGET_AVX2 SlabSplit split_avx2(std::size_t n, const Vec3* x, const double* rad, double dz,
                                       double max_slabs, std::uint32_t* first, std::uint8_t* count,
                                       double* w) {
    return split(n, x, rad, dz, max_slabs, first, count, w);
}
}  // namespace

SlabSplit split_two_slabs(std::size_t n, const Vec3* x, const double* rad, double dz,
                          double max_slabs, std::uint32_t* first, std::uint8_t* count, double* w) {
    if (cpu_has_avx2()) return split_avx2(n, x, rad, dz, max_slabs, first, count, w);
    return split(n, x, rad, dz, max_slabs, first, count, w);
}

}  // namespace efdem::dem
