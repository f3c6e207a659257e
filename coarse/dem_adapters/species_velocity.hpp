#pragma once
/// \file
/// The velocities of a colour lift (cpi.relabel_velocity = species). In a segregating bed each
/// species has its own mean vertical velocity at each height: the light spheres rise through the
/// heavy ones, 0.05-0.23 sqrt(g d_p) faster at U_s = 0.41 on the demo bed (t = 20-80), as much as
/// the spread of the vertical velocities there. A relabelled particle that keeps its velocity
/// brings its old species' drift into the new one, and the slip returns only as fast as drag
/// and contacts restore it (drag relaxation 0.8-4.5 time units, physics.md §3.3): in the bursts
/// after the lifts of a tall bed at U_s = 0.41 the lower light nodes rose 0.03 d_p per unit
/// slower than in the direct runs (of 0.07) over the first 5 units, 0.011 slower after
/// (bench/results/lift_velocity.md). Here each relabelled particle's vertical velocity is moved
/// by the local difference between the two species' means, so that each keeps its own.

#include <cstddef>
#include <cstdint>
#include <span>

#include "dem/system.hpp"

namespace efdem::coarse {

/// What carry_species_velocity() did.
struct SpeciesVelocityShift {
    std::size_t shifted = 0;  ///< relabelled particles whose vertical velocity was moved
    /// Relabelled particles in a band with fewer than the minimum of either species: velocity
    /// kept (the band's means too uncertain to move them by).
    std::size_t kept = 0;
    double max_shift = 0.0;  ///< largest |change| of a vertical velocity [sqrt(g d_p)]
};

/**
 * \brief Call before apply_colours(system, colours, observed, other): every particle whose
 *        species the colours change gets v_z += mean_new - mean_old.
 *
 * The means are of the vertical velocities of the two species (before any change) over the
 * particle's height band: the particles in height order cut into bands of `band_size` (the last
 * band takes the remainder when it would hold fewer than `band_size`). A band with fewer than
 * `min_per_species` particles of either species leaves its velocities alone. The species' mean
 * velocities in a band are then what they were (exactly when the relabelled particles had their
 * old species' mean). Horizontal velocities and spins are kept; contacts and forces are not
 * touched (apply_colours() refreshes the forces afterwards).
 *
 * Defaults: 200 particles per band (about 3 d_p of the 7.5 x 7.5 beds) leave a mixed band's
 * means a standard error of 0.1 of the velocity spread, below the slip they carry; 20 of a
 * species still leaves 0.22 of it.
 * \pre colours.size() == particles, values 0 or 1 (1: `observed`); every particle is of species
 *      `observed` or `other`; band_size >= 1.
 */
SpeciesVelocityShift carry_species_velocity(dem::System& system,
                                            std::span<const std::uint8_t> colours,
                                            dem::SpeciesId observed, dem::SpeciesId other,
                                            std::size_t band_size = 200,
                                            std::size_t min_per_species = 20);

}  // namespace efdem::coarse
