#pragma once
/// \file
/// SlabFields: the locally averaged solid fields phi(z) and u_s(z) on horizontal slabs, with
/// exact partial-volume weights (physics.md §4).
///
/// Slab j covers [j dz, (j+1) dz), j = 0..n-1, over the whole periodic cross-section (area
/// lx ly). Each sphere's volume is split exactly over the slabs it intersects: for a sphere of
/// radius R centred at z_c, the volume below a plane at height h is the spherical cap
///
///   G(h) = (pi R^3 / 3) (1 + t)^2 (2 - t),   t = clamp((h - z_c)/R, -1, 1),
///
/// and V_ij = G(top of slab j) - G(bottom of slab j). Then
///
///   phi_j   = sum_i V_ij / (lx ly dz)                        solid volume fraction [-]
///   u_s,j   = sum_i V_ij v_i / sum_i V_ij                    solid velocity [sqrt(g d_p)]
///
/// (u_s,j = 0 in an empty slab, where no particle has weight, so nothing reads it).
///
/// Decisions:
/// * The slabs start at the floor z = 0 and reach up to the top of the highest particle: n =
///   ceil(max_i (z_i + r_i)/dz) (at least 1). A particle ejected far above the bed adds
///   empty slabs; the cost stays O(N + n) and nothing else changes.
/// * The part of a sphere below z = 0 (a particle pressing into the floor, a contact overlap of
///   about 1e-3 d_p) is counted in slab 0, so every particle's whole volume is always in the
///   fields: sum_j phi_j lx ly dz = sum_i (pi/6) d_i^3 to round-off.
///
/// Per-particle weights are kept (a fixed stride of slots per particle) so that the force pass
/// reuses them: update() is the only place they are computed. When no sphere is wider than a
/// slab (the gas default: dz = d_p) each touches at most two slabs, the stride is 2, and a
/// vectorized kernel computes them (dem/gas/slab_split.hpp); the sums are then added in a second
/// pass, so that the first has independent iterations. No allocation once the arrays
/// have reached the particle count and the highest slab count seen (they only grow).
/// Not done here: the gas (dem/gas/gas_drag.hpp), any smoothing beyond the exact weights.
///
/// \code
/// SlabFields slabs(1.0, species.max_diameter());
/// slabs.update(particles, domain);
/// double phi_3 = slabs.phi()[3];
/// for (int k = 0; k < slabs.slab_count(i); ++k) use(slabs.first_slab(i) + k, slabs.weights(i)[k]);
/// \endcode

#include <algorithm>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "dem/domain.hpp"
#include "dem/particles.hpp"

namespace efdem::dem {

/// Volume of a sphere of radius r centred at height z_c that lies below the plane z = h: a cap
/// of height a = clamp(h - (z_c - r), 0, 2r), of volume (pi/3) a^2 (3r - a) [d_p^3]. At a = 2r
/// this is exactly the formula's whole sphere (4/3) pi r^3.
inline double sphere_volume_below(double h, double z_c, double r) {
    // min(max()) rather than std::clamp: the same value, without branches.
    const double a = std::min(std::max(h - (z_c - r), 0.0), 2.0 * r);
    return std::numbers::pi / 3.0 * a * a * (3.0 * r - a);
}

class SlabFields {
  public:
    /// `thickness` dz [d_p] (> 0); `max_diameter` of any particle [d_p], which bounds how many
    /// slabs one sphere can touch: floor(max_diameter/dz) + 2.
    SlabFields(double thickness, double max_diameter);

    /// Recomputes weights, phi and u_s from the current positions and velocities. O(N + n).
    void update(const Particles& p, const Domain& domain);

    double thickness() const { return dz_; }
    /// Number of slabs n; they cover [0, n dz).
    std::size_t size() const { return n_slabs_; }
    /// Top of the last slab, n dz [d_p].
    double z_top() const { return static_cast<double>(n_slabs_) * dz_; }
    /// Volume of one slab, lx ly dz [d_p^3].
    double slab_volume() const { return slab_volume_; }

    std::span<const double> phi() const { return {phi_.data(), n_slabs_}; }
    std::span<const Vec3> solid_velocity() const { return {u_s_.data(), n_slabs_}; }
    /// sum_i V_ij [d_p^3].
    std::span<const double> solid_volume() const { return {volume_.data(), n_slabs_}; }

    /// Largest number of slabs one particle can touch (the stride of the weight array).
    int max_slabs_per_particle() const { return stride_; }
    /// Index of the lowest slab particle i touches.
    std::uint32_t first_slab(std::size_t i) const { return first_[i]; }
    /// Number of slabs particle i touches (1..max_slabs_per_particle()).
    int slab_count(std::size_t i) const { return count_[i]; }
    /// V_ij for j = first_slab(i) + k, k < slab_count(i) [d_p^3].
    std::span<const double> weights(std::size_t i) const {
        return {weights_.data() + i * static_cast<std::size_t>(stride_),
                static_cast<std::size_t>(count_[i])};
    }

    /// Raw arrays for kernels: first slab, slab count, and weights at stride
    /// max_slabs_per_particle() per particle.
    const std::uint32_t* first_data() const { return first_.data(); }
    const std::uint8_t* count_data() const { return count_.data(); }
    const double* weight_data() const { return weights_.data(); }

  private:
    /// Running sums of one slab while the particles are scattered into it: volume and momentum.
    struct Sums {
        double volume, mx, my, mz;
    };
    /// Independent copies of the sums, used round-robin by consecutive particles: particles
    /// sorted in space mostly hit the same slab, and one copy would chain every addition to the
    /// previous one through memory.
    static constexpr std::size_t kLanes = 4;
    void grow(std::size_t n_slabs);
    static void accumulate(Sums& s, const Vec3& v, double w);
    /// First slab, slab count and weights of every particle; returns the slab count n. The
    /// common case (no sphere wider than a slab: at most two slabs each) has its own loop.
    std::size_t split_two(const Particles& p);
    std::size_t split_many(const Particles& p);
    /// Throws the RuntimeFailure naming the first particle too high (or NaN) for the slabs.
    [[noreturn]] [[gnu::noinline]] void report_blown_up(const Particles& p) const;
    /// Adds every particle's weights and weighted velocity into the slab sums.
    void scatter(const Particles& p);
    /// Slab sums -> phi, u_s, volume; clears the sums.
    void reduce();

    double dz_;
    int stride_;
    std::size_t n_slabs_ = 0;
    double slab_volume_ = 0;
    std::vector<std::uint32_t> first_;
    std::vector<std::uint8_t> count_;
    std::vector<double> weights_;
    std::vector<Sums> sums_;  ///< kLanes per slab, slab-major; all zero between updates
    std::vector<double> phi_;
    std::vector<double> volume_;
    std::vector<Vec3> u_s_;
};

}  // namespace efdem::dem
