#include "dem/slab_fields.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/contracts.hpp"
#include "core/error.hpp"

namespace efdem::dem {

namespace {
/// More slabs than this means a particle is absurdly high (a blown-up run), not a bed.
constexpr double kMaxSlabs = 1 << 24;

[[noreturn]] [[gnu::noinline]] void too_high(Tag tag, double z, double dz) {
    throw RuntimeFailure(
        fmt::format("slab fields: particle {} is at z = {:.6g}, which would need "
                    "more than {:.0f} slabs of thickness {:g}; the run has blown up",
                    tag, z, kMaxSlabs, dz));
}
}  // namespace

SlabFields::SlabFields(double thickness, double max_diameter)
    : dz_(thickness), stride_(static_cast<int>(std::floor(max_diameter / thickness)) + 2) {
    EFDEM_EXPECTS(thickness > 0 && max_diameter > 0);
    EFDEM_EXPECTS(stride_ <= 255);  // count_ is one byte per particle
}

void SlabFields::accumulate(Sums& s, const Vec3& v, double w) {
    s.volume += w;
    s.mx += v.x * w;
    s.my += v.y * w;
    s.mz += v.z * w;
}

void SlabFields::grow(std::size_t n_slabs) {
    // Amortized: at least doubles, so a particle rising slab by slab does not reallocate often.
    const std::size_t n = std::max(n_slabs, 2 * phi_.size());
    sums_.resize(n * kLanes, Sums{});
    phi_.resize(n);
    volume_.resize(n);
    u_s_.resize(n);
}

void SlabFields::update(const Particles& p, const Domain& domain) {
    const std::size_t n = p.size();
    if (first_.size() != n) {
        first_.resize(n);
        count_.resize(n);
        weights_.resize(n * static_cast<std::size_t>(stride_));
    }
    slab_volume_ = domain.area() * dz_;
    const Vec3* x = p.x().data();
    const Vec3* v = p.v().data();
    const double* rad = p.radius().data();
    const double inv_dz = 1.0 / dz_;
    std::size_t top = 1;  // slabs in use
    std::size_t capacity = phi_.size();
    Sums* sums = sums_.data();
    double* w = weights_.data();
    std::uint32_t* first = first_.data();  // locals: stores through them cannot alias members
    std::uint8_t* count = count_.data();
    const int stride = stride_;
    const double dz = dz_;

    for (std::size_t i = 0; i < n; ++i, w += stride) {
        const double z = x[i].z, r = rad[i];
        // Slab k holds [k dz, (k+1) dz): the sphere [z - r, z + r] touches slabs lo..hi with
        // lo = max(0, floor((z - r)/dz)) (whatever lies below z = 0 belongs to slab 0) and
        // hi = ceil((z + r)/dz) - 1 (a top exactly on a plane does not reach the slab above).
        // Integer truncation computes both (floor/ceil are slow without SSE4.1): for the
        // non-negative values that matter trunc = floor, and clamping handles the rest.
        const double t_top = (z + r) * inv_dz;
        if (!std::isfinite(t_top) || std::abs(t_top) >= kMaxSlabs) too_high(p.tag()[i], z, dz);
        const auto top_trunc = static_cast<std::int64_t>(t_top);
        const std::int64_t hi = top_trunc - (static_cast<double>(top_trunc) == t_top ? 1 : 0);
        const std::int64_t lo =
            std::max<std::int64_t>(0, static_cast<std::int64_t>((z - r) * inv_dz));
        const auto j0 = static_cast<std::uint32_t>(lo);
        const int c = static_cast<int>(std::clamp<std::int64_t>(hi, lo, lo + stride - 1) - lo) + 1;
        first[i] = j0;
        count[i] = static_cast<std::uint8_t>(c);
        const std::size_t end = j0 + static_cast<std::size_t>(c);
        if (end > capacity) {
            grow(end);
            capacity = phi_.size();
            sums = sums_.data();
        }
        top = std::max(top, end);

        // Exact partial volumes: differences of cap volumes at the interior planes, kept
        // monotone against round-off so that no weight is negative. With dz >= d a sphere cuts
        // at most one plane: that case (c = 2) is written out.
        const double full = sphere_volume_below(z + r, z, r);
        Sums* lane = sums + j0 * kLanes + (i % kLanes);
        if (c == 2) {
            const double g =
                std::min(sphere_volume_below(static_cast<double>(j0 + 1) * dz, z, r), full);
            w[0] = g;
            w[1] = full - g;
            accumulate(lane[0], v[i], w[0]);
            accumulate(lane[kLanes], v[i], w[1]);
            continue;
        }
        double below = 0.0;
        for (int k = 0; k + 1 < c; ++k) {
            const double plane = static_cast<double>(j0 + static_cast<std::uint32_t>(k) + 1) * dz;
            const double g = std::clamp(sphere_volume_below(plane, z, r), below, full);
            w[k] = g - below;
            below = g;
        }
        w[c - 1] = full - below;
        for (int k = 0; k < c; ++k, lane += kLanes) accumulate(*lane, v[i], w[k]);
    }
    n_slabs_ = top;

    // Reduce the lanes (and clear them for the next update) into phi and u_s.
    const double inv_slab = 1.0 / slab_volume_;
    for (std::size_t j = 0; j < n_slabs_; ++j) {
        Sums t{};
        for (std::size_t l = 0; l < kLanes; ++l) {
            Sums& s = sums[j * kLanes + l];
            t.volume += s.volume;
            t.mx += s.mx;
            t.my += s.my;
            t.mz += s.mz;
            s = Sums{};
        }
        volume_[j] = t.volume;
        phi_[j] = t.volume * inv_slab;
        // A weighted mean: division (not a reciprocal) cannot overflow for a tiny volume.
        u_s_[j] = t.volume > 0.0 ? Vec3{t.mx / t.volume, t.my / t.volume, t.mz / t.volume} : Vec3{};
    }
}

}  // namespace efdem::dem
