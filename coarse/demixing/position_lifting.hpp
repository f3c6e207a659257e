#pragma once
/// \file
/// Lifting by moving particles (docs/lifting_by_positions.md): for a bed whose two species
/// differ in size a label cannot switch without creating overlaps, so the target ICDF of the
/// observed species is realised by exchanging particles between heights, a large one against a
/// group of small ones of about its volume. What overlaps the exchange leaves is removed
/// afterwards by dem::relax_overlaps (dem/beds/overlap_relaxation.hpp), with the heights held.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "coarse/demixing/colour_lifting.hpp"  // LiftStatus
#include "coarse/demixing/lift_plan.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "core/rng.hpp"
#include "core/vec3.hpp"

namespace efdem::coarse {

/// The two species as position lifting sees them: kLight = observed, kHeavy = the other.
struct TwoSizes {
    double observed_diameter = 1.0;  ///< [d_p]
    double other_diameter = 1.0;     ///< [d_p]
    double observed_mass = 1.0;      ///< [rho_s d_p^3]
    double other_mass = 1.0;         ///< [rho_s d_p^3]
    double lx = 1.0;                 ///< periodic lengths of the box [d_p]
    double ly = 1.0;
    /// The large species observed: how far [d_p] an observed particle may lie from its rank's
    /// height and stay where it is (step 2b); every node then ends within it of the target.
    double resolution = 0.1;
};

struct PositionLiftResult {
    LiftStatus status = LiftStatus::rejected;
    std::vector<Vec3> positions;      ///< new positions (the input when rejected), x, y wrapped
    std::vector<Vec3> velocities;     ///< new velocities (momentum of each exchange kept)
    std::vector<std::uint8_t> moved;  ///< 1 for a particle placed elsewhere
    std::size_t n_exchanges = 0;      ///< large particles exchanged, each against a group
    std::size_t n_moved = 0;          ///< particles placed elsewhere (large and small)
    /// Volume ratio large/small rounded to the group size it implies on average
    /// (1 for equal sizes: the exchanges are swaps of two particles).
    double volume_ratio = 1.0;
    /// The target actually aimed at (after repair and clipping), as in colour lifting.
    Eigen::VectorXd target;
    /// Q of the observed heights after the exchange (before any relaxation) [d_p].
    Eigen::VectorXd achieved_icdf;
    double max_deviation = 0.0;  ///< max_i |achieved_icdf_i - target_i| [d_p]
    /// Largest |volume gained| by one interval of the plan, in units of the small volume: the
    /// exchanges keep each interval's solid volume to within the rounding of the groups.
    double max_volume_change = 0.0;
    /// Kinetic energy after - before [rho_s d_p^4 / (d_p/g) = m g d_p for m in rho_s d_p^3];
    /// zero momentum change when a group's mass equals the large particle's.
    double kinetic_energy_change = 0.0;
    double momentum_change = 0.0;  ///< |total momentum after - before|
    RepairReport repair;
    int n_short_intervals = 0;
    std::string message;

    bool applied() const { return status != LiftStatus::rejected; }
};

/**
 * \brief Moves particles so that the ICDF of the observed species (kLight) approaches
 *        `target_icdf`, keeping every interval's solid volume.
 *
 * 1. plan_lift: the repaired target, the intervals between its nodes and the observed count
 *    each must gain or lose (as colour lifting).
 * 2. With v_L/v_S = rho >= 1 the volume ratio of the large species to the small, each exchange
 *    trades one large particle against a group of about rho small ones.
 *    a. The small species observed: the observed particles that must move are listed by
 *       interval, lowest first, for the intervals that lose them and those that gain them; the
 *       M moves are cut into T = round(M / rho) consecutive groups (sizes differing by at most
 *       one), each group exchanged against a large particle of the interval its moves go to
 *       (the T picked evenly along the receiving list). Lowest with lowest: the monotone
 *       matching, as colour lifting's switches are.
 *    b. The large species observed, rank by rank (rank_windows.hpp): the observed particles
 *       that lie in their rank's window (sizes.resolution) stay; the others, lowest first, go to
 *       the free ranks' heights, lowest first, each against a group of
 *       round(rho (t + 1)) - round(rho t) small particles from the interval of that height.
 *       Every node then ends within sizes.resolution of the target (however few the observed
 *       particles: counts alone leave a node anywhere between its neighbours' heights).
 * 3. A group is compact: a random seed among its interval's candidates, then the nearest others
 *    (periodic in x, y) in the intervals of its moves (wider by one interval each side while too
 *    few; in 2b nearest to the point at the seed's x, y and the new height). The large particle
 *    goes to the group's centroid (2b: the centroid's x, y at its rank's height); the group goes
 *    to the large particle's place, its offsets from the centroid scaled so that their RMS is
 *    that of points filling the large particle's sphere (sqrt(3/5) (R_L - r_S)), never
 *    enlarged. Velocities:
 *    the large particle takes the group's mean velocity, each of the group the large
 *    particle's plus its own deviation from that mean: momentum and kinetic energy are exact
 *    when the group's mass equals the large particle's (otherwise the change is reported).
 *    Angular velocities stay.
 * 4. achieved_icdf from the new heights. With equal sizes every exchange is a swap of two
 *    particles, the counts are those of colour lifting, and there is no overlap to relax.
 *
 * The exchange leaves overlaps of up to R_L - r_S where a group was squeezed into a large
 * particle's place and where a large one took a group's: dem::relax_overlaps removes them.
 * Accuracy: small observed, the count below each node is off by at most about rho/2 from the
 * plan's (the rounding of the groups) and each moved particle lies within R_L of where the plan
 * puts it; large observed, every node within sizes.resolution of the target (unless a group
 * found no small particle left); measured in tests/coarse/test_position_lifting.cpp.
 *
 * \pre positions, velocities, colours of one size; colours in {kHeavy, kLight};
 *      target_icdf.size() == grid.size(); the two diameters > 0 with a ratio of at most 4.
 */
PositionLiftResult lift_positions(const Eigen::VectorXd& target_icdf,
                                  std::span<const Vec3> positions, std::span<const Vec3> velocities,
                                  std::span<const std::uint8_t> colours, const TwoSizes& sizes,
                                  const ProbabilityGrid& grid, RandomStream& rng);

}  // namespace efdem::coarse
