#pragma once
/// \file
/// NeighborList: a half Verlet list built with a cell grid, rebuilt when any particle has moved
/// more than half the skin since the last build (LAMMPS `neigh_modify every 1 check yes`).
///
/// At every build the particles are wrapped into the periodic box and *sorted by cell*, so that
/// particles close in space are close in memory (the force loop then reads mostly cached data).
/// The caller receives the permutation to carry per-particle data (contact history) along.
///
/// A pair (i, j) is listed once, under the smaller index i, when |x_i - x_j| < r_i + r_j + skin
/// for the nearest periodic image. Each entry packs j and the image of j that is meant:
/// entry = (j << 4) | code, and the separation is x_i - x_j - shift(code).

#include <cstdint>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "dem/domain.hpp"
#include "dem/particles.hpp"

namespace efdem::dem {

class NeighborList {
  public:
    using Entry = std::uint32_t;
    static constexpr int kCodeBits = 4;
    static constexpr Entry kCodeMask = (1u << kCodeBits) - 1;
    static constexpr std::size_t kMaxParticles = std::size_t{1} << (32 - kCodeBits);

    /// `max_diameter`: largest particle diameter [d_p]; `skin`: extra distance [d_p].
    NeighborList(double max_diameter, double skin);

    double skin() const { return skin_; }
    /// Largest distance at which two particles can be listed: max_diameter + skin.
    double cutoff() const { return cutoff_; }

    /// True if some particle moved more than skin/2 since the last build (or none was made).
    bool needs_rebuild(const Particles& p) const;

    /// Wraps positions into the box, sorts particles by cell (permuting `p`; `new_to_old`
    /// receives the permutation applied), and rebuilds the list.
    void build(Particles& p, const Domain& domain, std::vector<Index>& new_to_old);

    /// Rebuilds the list from saved reference positions (those of the last build, in the current
    /// particle order) without wrapping or sorting: the list is then identical to the one built
    /// at that time. Used by restarts to continue bit for bit.
    void rebuild_from_reference(const Particles& p, const Domain& domain,
                                std::span<const Vec3> reference_positions);

    std::span<const std::uint32_t> offsets() const { return offsets_; }  ///< size n + 1
    std::span<const Entry> entries() const { return entries_; }
    /// The 9 periodic image shifts, indexed by code.
    const Vec3* shifts() const { return shifts_; }
    /// Positions at the last build (current particle order).
    std::span<const Vec3> reference_positions() const { return x_build_; }

    static Index neighbor(Entry e) { return e >> kCodeBits; }
    static unsigned code(Entry e) { return e & kCodeMask; }

    std::size_t size() const { return entries_.size(); }
    long builds() const { return builds_; }
    std::size_t bytes() const;

  private:
    void bin(const Particles& p, const Domain& domain, std::span<const Vec3> x);
    void build_pairs(const Particles& p, const Domain& domain, std::span<const Vec3> x);

    double max_diameter_;
    double skin_;
    double cutoff_;
    long builds_ = 0;
    std::vector<std::uint32_t> offsets_;
    std::vector<Entry> entries_;
    std::vector<Vec3> x_build_;
    Vec3 shifts_[9];

    // Cell grid of the last binning.
    int nx_ = 1, ny_ = 1, nz_ = 1;
    double cell_x_ = 1, cell_y_ = 1, cell_z_ = 1, z_lo_ = 0;
    std::vector<std::uint32_t> cell_of_;  ///< cell of each particle
    std::vector<std::uint32_t>
        cell_start_;  ///< first particle of each cell (sorted order), size ncell + 1
};

}  // namespace efdem::dem
