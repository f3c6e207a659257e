#pragma once
/// \file
/// Removing overlaps that a rearrangement of the particles left (position lifting,
/// coarse/demixing/position_lifting.hpp): a minimisation of the overlap energy with no gravity,
/// no gas and every particle's height held near where it was put, so that the coarse variable
/// (the heights of one species) stays where the lift put it.

#include "dem/domain.hpp"
#include "dem/particles.hpp"

namespace efdem::dem {

struct OverlapRelaxationSettings {
    /// Largest overlap left, as a fraction of the pair's mean diameter (walls: of the diameter).
    /// 1e-4 is the overlap of spheres at the bottom of a 50 d_p bed under its weight with
    /// kn = 2e5; a pair left there stores 0.5 kn (1e-4 d)^2 = 1e-3 m g d_p, against the 0.1
    /// of the watchdog (watchdog.max_overlap), which would store 1e3.
    double tolerance = 1e-4;
    /// How far a particle's height may move from where it was put [d_p].
    double height_band = 0.25;
    long max_iterations = 20000;
};

struct OverlapRelaxationReport {
    double max_overlap_before = 0.0;  ///< as a fraction of the pair's mean diameter
    double max_overlap_after = 0.0;
    double max_displacement = 0.0;   ///< largest distance a particle moved [d_p]
    double max_height_change = 0.0;  ///< largest |z after - z before| [d_p]
    long iterations = 0;
    bool converged = false;  ///< max_overlap_after <= tolerance
};

/**
 * \brief Moves the particles apart until no overlap exceeds `settings.tolerance`, each height
 *        held within `settings.height_band` of where it was.
 *
 * Minimises E = sum 1/2 delta^2 over the overlapping pairs (periodic images in x, y) and the
 * floor (and the lid) by Jacobi steps: each particle moves by the sum of its overlap vectors
 * (delta along the line of centres) divided by twice its count of overlaps, then its height is
 * clamped into its band. A lone pair separates in one step; a particle pressed from many
 * sides moves by the mean push, which keeps a dense cluster from oscillating. Velocities, spins
 * and the order of `p` are unchanged; only positions move. Not converged after
 * max_iterations: the report says so and the positions are those reached (the caller decides:
 * a lift rejects its jump).
 *
 * Cost per step: one pass over a Verlet list (built with NeighborList on a copy, rebuilt when
 * a particle moved half the skin); measured in tests/dem/test_overlap_relaxation.cpp.
 */
OverlapRelaxationReport relax_overlaps(Particles& p, const Domain& domain,
                                       const OverlapRelaxationSettings& settings = {});

}  // namespace efdem::dem
