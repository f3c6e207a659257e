#include "dem/gas/slab_fields.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/contracts.hpp"
#include "core/error.hpp"
#include "dem/gas/slab_split.hpp"

namespace efdem::dem {

namespace {
/// More slabs than this means a particle is absurdly high (a blown-up run), not a bed.
constexpr double kMaxSlabs = 1 << 24;

}  // namespace

SlabFields::SlabFields(double thickness, double max_diameter)
    : dz_(thickness),
      stride_(max_diameter <= thickness
                  ? 2  // a sphere no wider than a slab cuts at most one plane
                  : static_cast<int>(std::floor(max_diameter / thickness)) + 2) {
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
    const std::size_t top = stride_ == 2 ? split_two(p) : split_many(p);
    if (top > phi_.size()) grow(top);
    n_slabs_ = top;
    scatter(p);
    reduce();
}

std::size_t SlabFields::split_two(const Particles& p) {
    // No store into shared sums here: the iterations are independent (scatter() adds up).
    const SlabSplit r = split_two_slabs(p.size(), p.x().data(), p.radius().data(), dz_, kMaxSlabs,
                                        first_.data(), count_.data(), weights_.data());
    if (r.out_of_range) report_blown_up(p);
    return r.top;
}

std::size_t SlabFields::split_many(const Particles& p) {
    const std::size_t n = p.size();
    const Vec3* x = p.x().data();
    const double* rad = p.radius().data();
    const int stride = stride_;
    double* w = weights_.data();
    const double dz = dz_, inv_dz = 1.0 / dz_;
    std::size_t top = 1;
    for (std::size_t i = 0; i < n; ++i, w += stride) {
        const double z = x[i].z, r = rad[i];
        // The slab range as in split_two().
        const double t_top = (z + r) * inv_dz;
        if (!std::isfinite(t_top) || std::abs(t_top) >= kMaxSlabs) report_blown_up(p);
        const auto top_trunc = static_cast<std::int64_t>(t_top);
        const std::int64_t hi = top_trunc - (static_cast<double>(top_trunc) == t_top ? 1 : 0);
        const std::int64_t lo =
            std::max<std::int64_t>(0, static_cast<std::int64_t>((z - r) * inv_dz));
        const auto j0 = static_cast<std::uint32_t>(lo);
        const int c = static_cast<int>(std::clamp<std::int64_t>(hi, lo, lo + stride - 1) - lo) + 1;
        first_[i] = j0;
        count_[i] = static_cast<std::uint8_t>(c);
        top = std::max(top, j0 + static_cast<std::size_t>(c));
        // Differences of cap volumes at the interior planes, kept monotone against round-off.
        const double full = sphere_volume_below(z + r, z, r);
        double below = 0.0;
        for (int k = 0; k + 1 < c; ++k) {
            const double plane = static_cast<double>(j0 + static_cast<std::uint32_t>(k) + 1) * dz;
            const double g = std::clamp(sphere_volume_below(plane, z, r), below, full);
            w[k] = g - below;
            below = g;
        }
        w[c - 1] = full - below;
    }
    return top;
}

void SlabFields::report_blown_up(const Particles& p) const {
    const double inv_dz = 1.0 / dz_;  // the same test as the loops'
    for (std::size_t i = 0; i < p.size(); ++i) {
        const double z = p.x()[i].z;
        const double t = (z + p.radius()[i]) * inv_dz;
        if (std::isnan(t))  // tested first, and not formatted: a NaN compare or print may trap
            throw RuntimeFailure(fmt::format(
                "slab fields: particle {} is at z = NaN; the run has blown up", p.tag()[i]));
        if (std::isinf(t) || std::abs(t) >= kMaxSlabs)
            throw RuntimeFailure(
                fmt::format("slab fields: particle {} is at z = {:.6g}, which would need "
                            "more than {:.0f} slabs of thickness {:g}; the run has blown up",
                            p.tag()[i], z, kMaxSlabs, dz_));
    }
    detail::contract_violation("invariant", "report_blown_up() finds a particle out of range",
                               __FILE__, __LINE__);
}

void SlabFields::scatter(const Particles& p) {
    const std::size_t n = p.size();
    const Vec3* v = p.v().data();
    const std::uint32_t* first = first_.data();
    const std::uint8_t* count = count_.data();
    const double* w = weights_.data();
    const std::size_t stride = static_cast<std::size_t>(stride_);
    Sums* sums = sums_.data();
    for (std::size_t i = 0; i < n; ++i, w += stride) {
        Sums* lane = sums + first[i] * kLanes + (i % kLanes);
        accumulate(lane[0], v[i], w[0]);
        for (int k = 1; k < count[i]; ++k)  // most spheres cut one plane: one more slab
            accumulate(lane[static_cast<std::size_t>(k) * kLanes], v[i], w[k]);
    }
}

void SlabFields::reduce() {
    // Reduce the lanes (and clear them for the next update) into phi and u_s.
    const double inv_slab = 1.0 / slab_volume_;
    Sums* sums = sums_.data();
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
