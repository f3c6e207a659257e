#include "dem/beds/bed_observation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/contracts.hpp"
#include "dem/beds/bed_diagnostics.hpp"

namespace efdem::dem {

namespace {
constexpr std::size_t kScalars = 4;  // Delta P, ratio, H, M
}

std::size_t BedObservation::packed_size(const BedObservationSettings& s) {
    return kScalars + s.species + s.profile_slabs;
}

std::vector<double> BedObservation::pack() const {
    std::vector<double> out{pressure_drop, pressure_drop_ratio, height, mixing_index};
    out.insert(out.end(), species_height.begin(), species_height.end());
    out.insert(out.end(), solid_fraction.begin(), solid_fraction.end());
    return out;
}

BedObservation BedObservation::unpack(std::span<const double> v, const BedObservationSettings& s) {
    EFDEM_EXPECTS(v.size() == packed_size(s));
    BedObservation o;
    o.pressure_drop = v[0];
    o.pressure_drop_ratio = v[1];
    o.height = v[2];
    o.mixing_index = v[3];
    const auto species_end = v.begin() + static_cast<std::ptrdiff_t>(kScalars + s.species);
    o.species_height.assign(v.begin() + kScalars, species_end);
    o.solid_fraction.assign(species_end, v.end());
    return o;
}

BedObservation observe_bed(const System& system, const BedObservationSettings& s) {
    const Particles& p = system.particles();
    BedObservation o;
    o.pressure_drop = pressure_drop(system);
    const double w = weight_per_area(system);
    o.pressure_drop_ratio = w > 0 ? o.pressure_drop / w : 0.0;
    o.height = bed_height(p);
    o.mixing_index = lacey_mixing_index(p, s.mixing_species, s.mixing_layer);
    std::vector<double> sum(s.species, 0.0), count(s.species, 0.0);
    const auto x = p.x();
    const auto sp = p.species();
    for (std::size_t i = 0; i < x.size(); ++i)
        if (sp[i] < s.species) {
            sum[sp[i]] += x[i].z;
            count[sp[i]] += 1;
        }
    o.species_height.resize(s.species);
    for (std::size_t k = 0; k < s.species; ++k)
        o.species_height[k] =
            count[k] > 0 ? sum[k] / count[k] : std::numeric_limits<double>::quiet_NaN();
    o.solid_fraction = solid_fraction_profile(p, system.domain(), s.profile_dz, s.profile_slabs);
    return o;
}

std::size_t default_profile_slabs(const System& system, double dz) {
    EFDEM_EXPECTS(dz > 0);
    double volume = 0;
    for (double r : system.particles().radius()) volume += 4.0 / 3.0 * std::numbers::pi * r * r * r;
    const double solid_height = volume / system.domain().area();
    return std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(3.0 * solid_height / dz)));
}

}  // namespace efdem::dem
