#pragma once
/// \file
/// Applying a lifted colour assignment to a DEM realization (physics.md §9 step 4): only species
/// labels change, and with them mass and inertia; positions, velocities, spins and contact
/// histories are kept.

#include <cstdint>
#include <span>

#include "dem/system.hpp"

namespace efdem::coarse {

/// Sets species `observed` where colours[i] == 1 and `other` where colours[i] == 0, for the
/// particles in the realization's current order (the order heights_and_colours() reported).
/// Returns the number of particles whose species changed. The system's forces are refreshed
/// once (masses changed). \pre colours.size() == particles, values 0 or 1.
std::size_t apply_colours(dem::System& system, std::span<const std::uint8_t> colours,
                          dem::SpeciesId observed, dem::SpeciesId other);

}  // namespace efdem::coarse
