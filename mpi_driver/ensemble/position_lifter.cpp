#include "mpi_driver/ensemble/position_lifter.hpp"

#include <utility>
#include <vector>

#include <fmt/format.h>

#include "coarse/demixing/lift_plan.hpp"
#include "coarse/demixing/position_lifting.hpp"
#include "core/contracts.hpp"

namespace efdem::mpi_driver {

std::vector<double> pack_positions(std::span<const Vec3> x, std::span<const Vec3> v) {
    EFDEM_EXPECTS(x.size() == v.size());
    std::vector<double> reals;
    reals.reserve(6 * x.size());
    for (const std::span<const Vec3> field : {x, v})
        for (const Vec3& a : field) reals.insert(reals.end(), {a.x, a.y, a.z});
    return reals;
}

std::vector<Vec3> unpack_vectors(const std::vector<double>& reals, std::size_t first,
                                 std::size_t n) {
    EFDEM_EXPECTS(reals.size() >= 3 * (first + n));
    std::vector<Vec3> out(n);
    for (std::size_t i = 0; i < n; ++i)
        out[i] = {reals[3 * (first + i)], reals[3 * (first + i) + 1], reals[3 * (first + i) + 2]};
    return out;
}

PositionLifter::PositionLifter(dem::SpeciesTable species, dem::SpeciesId observed,
                               dem::SpeciesId other, dem::Domain domain,
                               dem::OverlapRelaxationSettings relaxation, double resolution)
    : species_(std::move(species)),
      observed_(observed),
      other_(other),
      domain_(domain),
      relaxation_(relaxation),
      resolution_(resolution) {
    EFDEM_EXPECTS(resolution > 0);
}

LiftOutcome PositionLifter::lift(const Eigen::VectorXd& target, const LiftPayload& input,
                                 const coarse::ProbabilityGrid& grid, RandomStream& rng) const {
    const std::size_t n = input.bytes.size();
    EFDEM_EXPECTS(input.reals.size() == 6 * n);
    const std::vector<Vec3> x = unpack_vectors(input.reals, 0, n);
    const std::vector<Vec3> v = unpack_vectors(input.reals, n, n);
    const coarse::TwoSizes sizes{species_[observed_].diameter,
                                 species_[other_].diameter,
                                 species_.mass(observed_),
                                 species_.mass(other_),
                                 domain_.lx,
                                 domain_.ly,
                                 resolution_};
    const coarse::PositionLiftResult r =
        coarse::lift_positions(target, x, v, input.bytes, sizes, grid, rng);

    LiftOutcome out;
    out.payload.reals = input.reals;  // as it was, unless the lift is made below
    out.payload.bytes.assign(n, 0);
    out.max_deviation = r.max_deviation;
    out.message = r.message;
    if (!r.applied()) return out;
    out.deviation = r.achieved_icdf - r.target;
    if (r.n_moved == 0) return out;

    // The exchanged state as particles of the scene's species, relaxed with the heights held.
    dem::Particles p;
    p.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
        p.add(static_cast<dem::Tag>(i), r.positions[i], r.velocities[i],
              input.bytes[i] == coarse::kLight ? observed_ : other_, species_);
    const dem::OverlapRelaxationReport relax = dem::relax_overlaps(p, domain_, relaxation_);
    if (!relax.converged) {
        out.failure = fmt::format(
            "{} exchanges left overlaps the relaxation could not remove with the heights held "
            "within {:g} d_p: {:.3g} of a pair's diameter after {} steps (tolerance {:g})",
            r.n_exchanges, relaxation_.height_band, relax.max_overlap_after, relax.iterations,
            relaxation_.tolerance);
        out.deviation.resize(0);
        return out;
    }
    out.payload.reals = pack_positions(p.x(), r.velocities);
    out.payload.bytes = r.moved;
    out.changed = static_cast<long>(r.n_moved);
    std::vector<double> z(n);
    for (std::size_t i = 0; i < n; ++i) z[i] = p.x()[i].z;
    out.deviation = coarse::observed_icdf(z, input.bytes, grid) - r.target;
    out.max_deviation = out.deviation.cwiseAbs().maxCoeff();
    // The deviation before and after the relaxation tells the exchange's error from what the
    // relaxation moved (max over the p-grid, d_p).
    const std::string what = fmt::format(
        "{} particles moved in {} exchanges; overlaps {:.2g} -> {:.2g} of a diameter in {} "
        "relaxation steps; largest deviation from the target {:.2g} -> {:.2g} d_p; kinetic "
        "energy {:+.3g} m g d_p",
        r.n_moved, r.n_exchanges, relax.max_overlap_before, relax.max_overlap_after,
        relax.iterations, r.max_deviation, out.max_deviation, r.kinetic_energy_change);
    out.message = out.message.empty() ? what : out.message + "; " + what;
    return out;
}

}  // namespace efdem::mpi_driver
