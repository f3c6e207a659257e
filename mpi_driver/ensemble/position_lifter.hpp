#pragma once
/// \file
/// PositionLifter (cpi.lift_by = positions): the root's lifting of a bed of two sizes by moving
/// particles (docs/lifting_by_positions.md): coarse::lift_positions exchanges large particles
/// against groups of small ones, dem::relax_overlaps removes the overlaps that leaves with the
/// heights held. A relaxation that does not converge leaves the realization as it was and says
/// why (LiftOutcome::failure): the adaptive integrator rejects the jump.

#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "dem/beds/overlap_relaxation.hpp"
#include "dem/domain.hpp"
#include "dem/species.hpp"
#include "mpi_driver/ensemble/realization.hpp"

namespace efdem::mpi_driver {

/// The reals of a lift by positions (DemRealization's payload both ways): x, y, z of every
/// particle, then its velocity.
std::vector<double> pack_positions(std::span<const Vec3> x, std::span<const Vec3> v);
/// Vectors first .. first + n - 1 of such reals (0: the positions, n: the velocities).
std::vector<Vec3> unpack_vectors(const std::vector<double>& reals, std::size_t first,
                                 std::size_t n);

class PositionLifter final : public Lifter {
  public:
    /// The species table and box of the realizations (the same in every one); `observed`,
    /// `other`: the species whose ICDF is the coarse variable, and the other. When the observed
    /// species is the larger, `resolution` [d_p] is how far each observed particle may lie from
    /// its rank's height after the exchange (coarse::TwoSizes::resolution).
    PositionLifter(dem::SpeciesTable species, dem::SpeciesId observed, dem::SpeciesId other,
                   dem::Domain domain, dem::OverlapRelaxationSettings relaxation = {},
                   double resolution = 0.1);
    /// input: DemRealization::lift_input with lift_by_positions (x, v; colours). Output: new
    /// x, v (reals) and one moved flag per particle (bytes); changed = particles moved;
    /// max_deviation after the relaxation; the message says what the exchange and the
    /// relaxation did (exchanges, overlaps before and after, kinetic energy injected).
    LiftOutcome lift(const Eigen::VectorXd& target, const LiftPayload& input,
                     const coarse::ProbabilityGrid& grid, RandomStream& rng) const override;
    const char* changed_what() const override { return "particles moved"; }

  private:
    dem::SpeciesTable species_;
    dem::SpeciesId observed_, other_;
    dem::Domain domain_;
    dem::OverlapRelaxationSettings relaxation_;
    double resolution_;
};

}  // namespace efdem::mpi_driver
