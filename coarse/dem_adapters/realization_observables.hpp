#pragma once
/// \file
/// Observables of one DEM realization (restriction, physics.md §8): what the coarse layer reads
/// from the particles. Read-only: nothing here changes a realization.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "coarse/demixing/probability_grid.hpp"
#include "dem/particles.hpp"

namespace efdem::coarse {

/// Heights (particle-centre z [d_p]) and colours (1 = the observed species, 0 = any other) of all
/// particles, in the realization's current particle order: what colour lifting needs.
struct HeightsAndColours {
    std::vector<double> heights;
    std::vector<std::uint8_t> colours;
};
HeightsAndColours heights_and_colours(const dem::Particles& particles, dem::SpeciesId observed);

/// ICDF of the heights of `species` on the p-grid [d_p] (e.g. the light particles: Q_L).
/// \pre the species has at least one particle.
Eigen::VectorXd species_icdf(const dem::Particles& particles, dem::SpeciesId species,
                             const ProbabilityGrid& grid);

/// ICDF of the N/2 highest particles regardless of species (Q_top of physics.md §8, Q11): the
/// bound Q_top >= Q_L holds node by node when the light species has N/2 particles.
Eigen::VectorXd top_half_icdf(const dem::Particles& particles, const ProbabilityGrid& grid);

/// The whole bed's profile (coarse/demixing/whole_bed_profile.hpp): the lowest particle centre,
/// the ICDF of all heights at p = 0.01..0.99, the highest. \pre at least one particle.
Eigen::VectorXd whole_bed_profile(const dem::Particles& particles);

/// Height of the centre of mass of all particles [d_p]: the travelling-wave phase signal (§7).
double centre_of_mass_height(const dem::Particles& particles);

}  // namespace efdem::coarse
