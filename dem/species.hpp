#pragma once
/// \file
/// Species: the material of a particle (density, diameter) and the masses derived from it.
///
/// Units (physics.md §2): density in rho_s (the light species' density), diameter in d_p, mass in
/// rho_s d_p^3. A sphere of diameter d and density rho has m = rho pi d^3 / 6 and moment of
/// inertia I = m d^2 / 10 (solid sphere).

#include <cstdint>
#include <string>
#include <vector>

#include "core/bounds.hpp"

namespace efdem {
class Params;
}

namespace efdem::dem {

/// Allowed densities [rho_s] and diameters [d_p]: three decades either side of the reference
/// species (density 1, diameter 1). Wider ratios are almost always a unit mistake (a diameter
/// in metres, a density in kg/m^3), and they would push masses and contact times towards the
/// ends of the double range.
inline const Bounds kDensityRange = Bounds::closed(1e-3, 1e3);
inline const Bounds kDiameterRange = Bounds::closed(1e-3, 1e3);

/// Species index as stored per particle. Binary mixtures use 0 and 1; up to 255 are possible.
using SpeciesId = std::uint8_t;

struct Species {
    std::string name;
    double density = 1.0;   ///< [rho_s]
    double diameter = 1.0;  ///< [d_p]
};

/**
 * \brief The species of a scene and their derived per-particle quantities.
 *
 * Scene keys (all in scope `species`): `names` (words), `density` and `diameter` (one number
 * per name).
 * \code
 * species.names    = light heavy
 * species.density  = 1 2
 * species.diameter = 1 1
 * \endcode
 */
class SpeciesTable {
  public:
    SpeciesTable() = default;
    explicit SpeciesTable(std::vector<Species> species);
    static SpeciesTable from_params(const Params& scope);

    std::size_t size() const { return species_.size(); }
    const Species& operator[](SpeciesId s) const { return species_[s]; }
    /// Index of the species called `name`, or -1.
    int find(const std::string& name) const;

    double radius(SpeciesId s) const { return 0.5 * species_[s].diameter; }
    double mass(SpeciesId s) const;
    double inertia(SpeciesId s) const {
        return 0.1 * mass(s) * species_[s].diameter * species_[s].diameter;
    }
    double max_diameter() const;
    double min_mass() const;

  private:
    std::vector<Species> species_;
};

}  // namespace efdem::dem
