#pragma once
/// \file
/// BedObservation: what a fluidized-bed user looks at first, measured on one realization at a
/// sample (`observe.bed = true`): the pressure drop and its ratio to the bed weight per area,
/// the bed height, each species' mean height, the Lacey mixing index and the solid-fraction
/// profile phi(z). A pure function of the state (dem/beds/bed_diagnostics.hpp), packed into one
/// flat vector of fixed length so that an ensemble can gather it like the ICDF.

#include <cstddef>
#include <span>
#include <vector>

#include "dem/species.hpp"
#include "dem/system.hpp"

namespace efdem::dem {

/// How the bed quantities are measured (the observe.* keys of docs/scene_reference.md).
struct BedObservationSettings {
    double profile_dz = 1.0;        ///< slab thickness of phi(z) [d_p]
    std::size_t profile_slabs = 1;  ///< slabs of phi(z), from the floor: [0, slabs dz)
    double mixing_layer = 2.0;      ///< layer thickness of the Lacey index [d_p]
    SpeciesId mixing_species = 0;   ///< the species whose concentration the index follows
    std::size_t species = 2;        ///< species in the scene (one mean height each)
};

struct BedObservation {
    double pressure_drop = 0;        ///< Delta P across the bed [rho_s g d_p] (0 without gas_drag)
    double pressure_drop_ratio = 0;  ///< Delta P / (W / A) [-]: 1 for a fully supported bed
    double height = 0;               ///< height below which 99 % of the particle volume lies [d_p]
    double mixing_index = 0;         ///< Lacey index of mixing_species over layers [-]
    std::vector<double> species_height;  ///< number-weighted mean centre height, per species [d_p]
    std::vector<double> solid_fraction;  ///< phi of each slab [-]

    /// Length of the packed vector for `settings`.
    static std::size_t packed_size(const BedObservationSettings& settings);
    /// [Delta P, ratio, H, M, species heights..., phi...].
    std::vector<double> pack() const;
    /// \pre packed.size() == packed_size(settings).
    static BedObservation unpack(std::span<const double> packed,
                                 const BedObservationSettings& settings);
};

/// Measures `system` now. The weight uses the gravity effect's g (1 without one).
BedObservation observe_bed(const System& system, const BedObservationSettings& settings);

/// A default top of the phi(z) profile: three times the height the bed's solid volume would
/// fill at phi = 1 (about 1.8 times the packed bed, above the bed's expansion at U_s <= 0.6 on
/// the demo and paper beds), rounded up to whole slabs [slabs].
std::size_t default_profile_slabs(const System& system, double dz);

}  // namespace efdem::dem
