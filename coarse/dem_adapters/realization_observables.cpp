#include "coarse/dem_adapters/realization_observables.hpp"

#include <algorithm>
#include <utility>

#include "coarse/demixing/quantiles.hpp"
#include "coarse/demixing/whole_bed_profile.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

HeightsAndColours heights_and_colours(const dem::Particles& p, dem::SpeciesId observed) {
    HeightsAndColours out;
    out.heights.resize(p.size());
    out.colours.resize(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) {
        out.heights[i] = p.x()[i].z;
        out.colours[i] = p.species()[i] == observed ? 1 : 0;
    }
    return out;
}

Eigen::VectorXd species_icdf(const dem::Particles& p, dem::SpeciesId species,
                             const ProbabilityGrid& grid) {
    std::vector<double> z;
    z.reserve(p.size());
    for (std::size_t i = 0; i < p.size(); ++i)
        if (p.species()[i] == species) z.push_back(p.x()[i].z);
    EFDEM_EXPECTS(!z.empty());
    return quantiles(z, grid);
}

Eigen::VectorXd top_half_icdf(const dem::Particles& p, const ProbabilityGrid& grid) {
    EFDEM_EXPECTS(p.size() >= 2);
    std::vector<double> z(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) z[i] = p.x()[i].z;
    const std::size_t half = p.size() / 2;
    // The N/2 highest: everything from the (N - N/2)-th order statistic up.
    std::nth_element(z.begin(), z.begin() + static_cast<std::ptrdiff_t>(p.size() - half), z.end());
    std::vector<double> top(z.begin() + static_cast<std::ptrdiff_t>(p.size() - half), z.end());
    return quantiles(top, grid);
}

Eigen::VectorXd whole_bed_profile(const dem::Particles& p) {
    EFDEM_EXPECTS(p.size() >= 1);
    std::vector<double> z(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) z[i] = p.x()[i].z;
    return profile_of_heights(std::move(z));
}

double centre_of_mass_height(const dem::Particles& p) {
    double mz = 0, m = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        mz += p.mass()[i] * p.x()[i].z;
        m += p.mass()[i];
    }
    return m > 0 ? mz / m : 0.0;
}

}  // namespace efdem::coarse
