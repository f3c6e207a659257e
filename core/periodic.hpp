#pragma once
/// \file
/// The periodic directions of a box, x and y with lengths lx, ly (z is never periodic): the
/// wrap of a position into the box and the minimum image of a separation. One definition for
/// the DEM's domain (dem::Domain) and for a lift that moves particles
/// (coarse/demixing/position_lifting), which may not depend on dem/.

#include <cmath>

#include "core/vec3.hpp"

namespace efdem {

/// Maps a position into [0, lx) x [0, ly); z is unchanged. \pre lx, ly > 0.
inline Vec3 wrap_xy(Vec3 p, double lx, double ly) {
    p.x -= lx * std::floor(p.x / lx);
    p.y -= ly * std::floor(p.y / ly);
    // floor() of a value just below 0 can produce exactly lx; keep the half-open interval.
    if (p.x >= lx) p.x -= lx;
    if (p.y >= ly) p.y -= ly;
    return p;
}

/// The periodic image of a separation vector with |dx| <= lx/2, |dy| <= ly/2. \pre lx, ly > 0.
inline Vec3 minimum_image_xy(Vec3 d, double lx, double ly) {
    d.x -= lx * std::nearbyint(d.x / lx);
    d.y -= ly * std::nearbyint(d.y / ly);
    return d;
}

}  // namespace efdem
