#include "dem/slab_fields.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/contracts.hpp"
#include "core/error.hpp"

namespace efdem::dem {

namespace {
/// More slabs than this means a particle is absurdly high (a blown-up run), not a bed.
constexpr double kMaxSlabs = 1 << 24;
}  // namespace

SlabFields::SlabFields(double thickness, double max_diameter)
    : dz_(thickness), stride_(static_cast<int>(std::floor(max_diameter / thickness)) + 2) {
    EFDEM_EXPECTS(thickness > 0 && max_diameter > 0);
    EFDEM_EXPECTS(stride_ <= 255);  // count_ is one byte per particle
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

    // Pass 1: the slabs each particle touches, and how many slabs there are.
    double top = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        // Slab k holds [k dz, (k+1) dz); a sphere whose top lies exactly on a plane does not
        // reach the slab above it.
        const double hi = std::ceil((x[i].z + rad[i]) * inv_dz) - 1.0;
        if (!std::isfinite(hi) || hi >= kMaxSlabs)
            throw RuntimeFailure(fmt::format(
                "slab fields: particle {} is at z = {:.6g}, which would need more than {:.0f} slabs "
                "of thickness {:g}; the run has blown up",
                p.tag()[i], x[i].z, kMaxSlabs, dz_));
        const double lo = std::max(0.0, std::floor((x[i].z - rad[i]) * inv_dz));
        const double last = std::clamp(hi, lo, lo + stride_ - 1);
        first_[i] = static_cast<std::uint32_t>(lo);
        count_[i] = static_cast<std::uint8_t>(last - lo + 1);
        top = std::max(top, last);
    }
    n_slabs_ = static_cast<std::size_t>(top) + 1;
    if (phi_.size() < n_slabs_) {
        phi_.resize(n_slabs_);
        volume_.resize(n_slabs_);
        u_s_.resize(n_slabs_);
    }
    std::fill_n(volume_.begin(), n_slabs_, 0.0);
    std::fill_n(u_s_.begin(), n_slabs_, Vec3{});

    // Pass 2: exact partial volumes (differences of cap volumes at the interior planes; the
    // lowest slab also takes whatever lies below z = 0), accumulated into the slabs.
    double* w = weights_.data();
    for (std::size_t i = 0; i < n; ++i, w += stride_) {
        const double r = rad[i];
        const double full = 4.0 / 3.0 * std::numbers::pi * r * r * r;
        const std::uint32_t j0 = first_[i];
        const int c = count_[i];
        double below = 0.0;  // volume below the current plane, kept monotone against round-off
        for (int k = 0; k + 1 < c; ++k) {
            const double plane = static_cast<double>(j0 + static_cast<std::uint32_t>(k) + 1) * dz_;
            const double g = std::clamp(sphere_volume_below(plane, x[i].z, r), below, full);
            w[k] = g - below;
            below = g;
        }
        w[c - 1] = full - below;
        for (int k = 0; k < c; ++k) {
            volume_[j0 + static_cast<std::uint32_t>(k)] += w[k];
            u_s_[j0 + static_cast<std::uint32_t>(k)] += v[i] * w[k];
        }
    }
    const double inv_slab = 1.0 / slab_volume_;
    for (std::size_t j = 0; j < n_slabs_; ++j) {
        phi_[j] = volume_[j] * inv_slab;
        // A weighted mean: division (not a reciprocal) cannot overflow for a tiny volume.
        const double vol = volume_[j];
        const Vec3 m = u_s_[j];
        u_s_[j] = vol > 0.0 ? Vec3{m.x / vol, m.y / vol, m.z / vol} : Vec3{};
    }
}

}  // namespace efdem::dem
