#include "coarse/dem_adapters/species_velocity.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "core/contracts.hpp"

namespace efdem::coarse {

SpeciesVelocityShift carry_species_velocity(dem::System& system,
                                            std::span<const std::uint8_t> colours,
                                            dem::SpeciesId observed, dem::SpeciesId other,
                                            std::size_t band_size, std::size_t min_per_species) {
    dem::Particles& p = system.particles();
    const std::size_t n = p.size();
    EFDEM_EXPECTS(colours.size() == n && band_size >= 1);
    const auto species = p.species();
    const auto x = p.x();
    const auto v = p.v();
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return x[a].z < x[b].z; });

    SpeciesVelocityShift out;
    for (std::size_t start = 0; start < n;) {
        const std::size_t end = n - start < 2 * band_size ? n : start + band_size;
        double sum_observed = 0.0, sum_other = 0.0;
        std::size_t n_observed = 0, n_other = 0;
        for (std::size_t k = start; k < end; ++k) {
            const std::size_t i = order[k];
            EFDEM_EXPECTS(species[i] == observed || species[i] == other);
            if (species[i] == observed) {
                sum_observed += v[i].z;
                ++n_observed;
            } else {
                sum_other += v[i].z;
                ++n_other;
            }
        }
        const bool known = n_observed >= min_per_species && n_other >= min_per_species;
        // mean(observed) - mean(other): what a particle turning observed gains.
        const double slip = known ? sum_observed / static_cast<double>(n_observed) -
                                        sum_other / static_cast<double>(n_other)
                                  : 0.0;
        for (std::size_t k = start; k < end; ++k) {
            const std::size_t i = order[k];
            EFDEM_EXPECTS(colours[i] <= 1);
            const dem::SpeciesId want = colours[i] ? observed : other;
            if (want == species[i]) continue;
            if (!known) {
                ++out.kept;
                continue;
            }
            v[i].z += want == observed ? slip : -slip;
            ++out.shifted;
            out.max_shift = std::max(out.max_shift, std::abs(slip));
        }
        start = end;
    }
    return out;
}

}  // namespace efdem::coarse
