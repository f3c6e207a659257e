#pragma once
/// \file
/// Coordinates in which every vector is a strictly increasing ICDF (steady.coordinates = gaps,
/// docs/steady_states.md): u_0 = X_0 (the lowest node's height [d_p]) and
/// u_i = log(X_i - X_{i-1}) for i >= 1 (the logs of the gaps between neighbouring nodes).
/// A Newton step or a Krylov direction in u can then never make the lifted ICDF non-monotone;
/// only the bed's top and floor remain for the repair to clip.

#include "coarse/equation_free/steady/coarse_map.hpp"

namespace efdem::coarse {

/// Gaps below `floor` [d_p] (ties of a member's ICDF) are taken as `floor`, so that their log
/// stays finite. \pre floor > 0.
CoarseCoordinates icdf_gap_coordinates(double floor = 1e-3);

}  // namespace efdem::coarse
