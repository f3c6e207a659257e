#pragma once
/// \file
/// Domain: the box of one realization. Periodic in x and y with lengths lx, ly; a flat floor
/// (the gas distributor) at z = 0; optionally a reflecting lid at z = lid_height.
///
/// Positions are wrapped into [0, lx) x [0, ly) only when the neighbour list is rebuilt; between
/// rebuilds a particle may sit slightly outside (by less than half the skin), as in LAMMPS.

#include <cmath>
#include <limits>

#include "core/periodic.hpp"
#include "core/vec3.hpp"

namespace efdem {
class Params;
}

namespace efdem::dem {

/// Largest box length and lid height [d_p]. Positions are doubles: below 1e6 they keep an
/// absolute resolution of about 1e-10 d_p, far finer than the overlaps (1e-4 .. 1e-3 d_p) that
/// the contact forces are computed from. Beyond it contact forces lose digits.
inline constexpr double kMaxDomainLength = 1e6;

struct Domain {
    double lx = 1.0;                                              ///< periodic length in x [d_p]
    double ly = 1.0;                                              ///< periodic length in y [d_p]
    double lid_height = std::numeric_limits<double>::infinity();  ///< z of the lid, or +inf

    bool has_lid() const { return std::isfinite(lid_height); }
    double area() const { return lx * ly; }

    /// Maps a position into [0, lx) x [0, ly); z is unchanged.
    Vec3 wrap(Vec3 p) const { return wrap_xy(p, lx, ly); }
    /// The periodic image of a separation vector with |dx| <= lx/2, |dy| <= ly/2.
    Vec3 minimum_image(Vec3 d) const { return minimum_image_xy(d, lx, ly); }

    /// Reads `domain.lx`, `domain.ly` (required) and `domain.lid` (optional height), each in
    /// (0, kMaxDomainLength].
    static Domain from_params(const Params& scope);
};

}  // namespace efdem::dem
