#pragma once
/// \file
/// Particles: the structure-of-arrays store of one realization's spheres.
///
/// Each property is its own contiguous array (positions, velocities, ... are arrays of Vec3),
/// so a kernel streams only what it reads. Particles owns no physics: effects read and write
/// these arrays through a ForceContext; the integrator advances them.
///
/// Identity: `tag` is a particle's permanent id (stable across spatial sorting, restarts and
/// relabelling); the array index is not stable (the neighbour list re-sorts particles in space).

#include <cstdint>
#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "dem/species.hpp"

namespace efdem::dem {

/// Most particles one realization may hold (bed.count in all, or the atoms of bed.file). A
/// realization runs serially on one rank, and the paper's bed has 12,500 particles; a million
/// takes ~0.3 GB and seconds per hundred steps, so a larger bed is almost certainly a typo,
/// and refusing it keeps `efdem --check` from allocating it.
inline constexpr long kMaxRealizationParticles = 1'000'000;

using Index = std::uint32_t;  ///< particle index in the arrays (not stable; see tag)
using Tag = std::int64_t;     ///< permanent particle id

class Particles {
  public:
    std::size_t size() const { return x_.size(); }
    bool empty() const { return x_.empty(); }
    void reserve(std::size_t n);

    /// Appends a particle at rest (no spin) with the species' radius, mass and inertia.
    void add(Tag tag, const Vec3& position, const Vec3& velocity, SpeciesId species,
             const SpeciesTable& table);

    /// Changes a particle's species and with it its radius, mass and inertia; position,
    /// velocity and spin are kept (the lifting of physics.md §9 relies on this).
    void set_species(Index i, SpeciesId species, const SpeciesTable& table);

    /// Reorders every array so that new index k holds the particle that was at new_to_old[k].
    void permute(std::span<const Index> new_to_old);

    void zero_forces();

    // Array views. Kernels take .data() once per loop.
    std::span<Vec3> x() { return x_; }
    std::span<Vec3> v() { return v_; }
    std::span<Vec3> omega() { return omega_; }
    std::span<Vec3> force() { return f_; }
    std::span<Vec3> torque() { return torque_; }
    std::span<const Vec3> x() const { return x_; }
    std::span<const Vec3> v() const { return v_; }
    std::span<const Vec3> omega() const { return omega_; }
    std::span<const Vec3> force() const { return f_; }
    std::span<const Vec3> torque() const { return torque_; }
    std::span<const double> radius() const { return radius_; }
    std::span<const double> mass() const { return mass_; }
    std::span<const double> inv_mass() const { return inv_mass_; }
    std::span<const double> inertia() const { return inertia_; }
    std::span<const double> inv_inertia() const { return inv_inertia_; }
    std::span<const SpeciesId> species() const { return species_; }
    std::span<const Tag> tag() const { return tag_; }

    /// Raw pointers to what a contact or force kernel reads and writes, taken once per loop.
    struct KernelView {
        std::size_t n;
        const Vec3* x;
        const Vec3* v;
        const Vec3* omega;
        Vec3* force;
        Vec3* torque;
        const double* radius;
        const SpeciesId* species;
    };
    KernelView kernel_view() {
        return {size(),    x_.data(),      v_.data(),      omega_.data(),
                f_.data(), torque_.data(), radius_.data(), species_.data()};
    }

    /// Bytes held by the arrays (for memory-per-particle reports).
    std::size_t bytes() const;

  private:
    std::vector<Vec3> x_, v_, omega_, f_, torque_;
    std::vector<double> radius_, mass_, inv_mass_, inertia_, inv_inertia_;
    std::vector<SpeciesId> species_;
    std::vector<Tag> tag_;
};

}  // namespace efdem::dem
