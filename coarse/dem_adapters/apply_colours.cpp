#include "coarse/dem_adapters/apply_colours.hpp"

#include <vector>

#include "core/contracts.hpp"

namespace efdem::coarse {

std::size_t apply_colours(dem::System& system, std::span<const std::uint8_t> colours,
                          dem::SpeciesId observed, dem::SpeciesId other) {
    const auto species = system.particles().species();
    EFDEM_EXPECTS(colours.size() == species.size());
    std::vector<dem::Index> changed;
    std::vector<dem::SpeciesId> to;
    for (std::size_t i = 0; i < colours.size(); ++i) {
        EFDEM_EXPECTS(colours[i] <= 1);
        const dem::SpeciesId want = colours[i] ? observed : other;
        if (species[i] != want) {
            changed.push_back(static_cast<dem::Index>(i));
            to.push_back(want);
        }
    }
    if (!changed.empty()) system.set_species(changed, to);
    return changed.size();
}

}  // namespace efdem::coarse
