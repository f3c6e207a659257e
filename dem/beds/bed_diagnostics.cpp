#include "dem/beds/bed_diagnostics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/contracts.hpp"
#include "dem/body_forces/gravity.hpp"
#include "dem/gas/gas_drag.hpp"
#include "dem/gas/slab_fields.hpp"

namespace efdem::dem {

double pressure_drop(const System& system) {
    const auto* gas = dynamic_cast<const GasDrag*>(system.find_effect("gas_drag"));
    if (!gas) return 0.0;
    EFDEM_ASSERT(system.slab_fields() != nullptr);
    return gas->pressure_drop(*system.slab_fields(), system.particles());
}

double weight_per_area(const Particles& p, const Domain& domain, double g) {
    double m = 0;
    for (double mi : p.mass()) m += mi;
    return m * g / domain.area();
}

double weight_per_area(const System& system) {
    const auto* gravity = dynamic_cast<const Gravity*>(system.find_effect("gravity"));
    return weight_per_area(system.particles(), system.domain(), gravity ? gravity->g() : 1.0);
}

double bed_height(const Particles& p, double fraction) {
    EFDEM_EXPECTS(fraction > 0 && fraction <= 1);
    const auto x = p.x();
    const auto r = p.radius();
    if (x.empty()) return 0.0;
    double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
    double total = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        lo = std::min(lo, x[i].z - r[i]);
        hi = std::max(hi, x[i].z + r[i]);
        total += sphere_volume_below(x[i].z + r[i], x[i].z, r[i]);
    }
    const double target = fraction * total;
    // Volume below h is continuous and non-decreasing in h: bisect on [lo, hi]. (The iteration
    // bound stops the loop where 1e-9 is below the spacing of doubles near a huge height.)
    for (int it = 0; it < 200 && hi - lo > 1e-9; ++it) {
        const double mid = 0.5 * (lo + hi);
        double below = 0;
        for (std::size_t i = 0; i < x.size(); ++i) below += sphere_volume_below(mid, x[i].z, r[i]);
        (below < target ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

double center_of_mass_height(const Particles& p, int species) {
    const auto x = p.x();
    const auto m = p.mass();
    const auto sp = p.species();
    double mz = 0, mass = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
        if (species < 0 || sp[i] == species) {
            mz += m[i] * x[i].z;
            mass += m[i];
        }
    return mass > 0 ? mz / mass : 0.0;
}

std::vector<double> solid_fraction_profile(const Particles& p, const Domain& domain, double dz) {
    double d_max = 0;
    for (double r : p.radius()) d_max = std::max(d_max, 2 * r);
    SlabFields slabs(dz, d_max > 0 ? d_max : 1.0);
    slabs.update(p, domain);
    return {slabs.phi().begin(), slabs.phi().end()};
}

std::vector<double> solid_fraction_profile(const Particles& p, const Domain& domain, double dz,
                                           std::size_t slabs) {
    EFDEM_EXPECTS(slabs > 0);
    std::vector<double> phi = solid_fraction_profile(p, domain, dz);
    phi.resize(slabs, 0.0);
    return phi;
}

double lacey_mixing_index(const Particles& p, SpeciesId species, double layer) {
    EFDEM_EXPECTS(layer > 0);
    const auto x = p.x();
    const auto sp = p.species();
    std::vector<double> n, of_species;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const auto k = static_cast<std::size_t>(std::max(0.0, std::floor(x[i].z / layer)));
        if (k >= n.size()) {
            n.resize(k + 1, 0.0);
            of_species.resize(k + 1, 0.0);
        }
        n[k] += 1;
        if (sp[i] == species) of_species[k] += 1;
    }
    const double total = static_cast<double>(x.size());
    double in_species = 0, occupied = 0;
    for (std::size_t k = 0; k < n.size(); ++k) {
        in_species += of_species[k];
        if (n[k] > 0) occupied += 1;
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (total == 0 || in_species == 0 || in_species == total || occupied < 2) return nan;
    const double P = in_species / total;
    double s2 = 0;
    for (std::size_t k = 0; k < n.size(); ++k)
        if (n[k] > 0) {
            const double c = of_species[k] / n[k];
            s2 += n[k] * (c - P) * (c - P);
        }
    s2 /= total;
    const double s0 = P * (1 - P), sr = s0 / (total / occupied);
    return (s0 - s2) / (s0 - sr);
}

}  // namespace efdem::dem
