#pragma once
/// \file
/// Which particles a colour lift relabels (cpi.relabel = clustered). In a direct segregating bed
/// the light spheres are not spread at random among the heavy ones at their height: they gather
/// with other lights (the demo bed at U_s = 0.41, t = 40 and 80: of the neighbours within 1.15
/// contact distances of the lowest 30 % of the lights, 49-51 % are light where a random
/// arrangement of the same heights gives 39-42 %), and such lights rise faster than the others
/// at their height (bench/results/lift_clusters.md). A colour lift that draws the particles
/// it relabels at random puts new lights among heavies, alone. These counts let it grow the
/// clusters instead (coarse::SwitchOrder::By::light_neighbours).

#include <cstdint>
#include <vector>

#include "dem/domain.hpp"
#include "dem/particles.hpp"

namespace efdem::coarse {

/// Centre distance, in contact distances (r_i + r_j), within which two particles count as
/// neighbours: the touching ones and those about to touch or just parted.
inline constexpr double kNeighbourReach = 1.15;

/**
 * \brief For each particle, how many particles of species `observed` lie within
 *        `reach` (r_i + r_j) of its centre (nearest periodic image in x and y; the particle
 *        itself not counted), capped at 255.
 *
 * A cell grid of side >= reach × the largest diameter: O(N) for a bed of bounded density.
 * \pre reach > 0; the box's lateral lengths positive.
 */
std::vector<std::uint8_t> light_neighbour_counts(const dem::Particles& particles,
                                                 const dem::Domain& box, dem::SpeciesId observed,
                                                 double reach = kNeighbourReach);

}  // namespace efdem::coarse
