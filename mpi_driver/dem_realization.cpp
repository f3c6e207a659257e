#include "mpi_driver/dem_realization.hpp"

#include <algorithm>
#include <limits>

#include <fmt/format.h>

#include "coarse/colour_lifting.hpp"
#include "coarse/dem_adapters/apply_colours.hpp"
#include "coarse/dem_adapters/realization_observables.hpp"

namespace efdem::mpi_driver {

DemRealization::DemRealization(dem::System system, dem::SpeciesId observed, dem::SpeciesId other,
                               const RealizationOutput& output)
    : system_(std::move(system)), observed_(observed), other_(other), output_(output) {
    const std::string stem = fmt::format("{}_r{:04d}", output_.prefix, index());
    if (output_.vtk_every > 0) vtk_.emplace(output_.directory, stem);
    if (output_.thermo_every > 0) thermo_ = std::make_unique<dem::ThermoLog>(output_.directory / (stem + "_thermo.log"));
    after_sample(0);
}

Observation DemRealization::observe(const coarse::ProbabilityGrid& grid, bool top_half) const {
    const dem::Particles& p = system_.particles();
    Observation o;
    o.icdf = coarse::species_icdf(p, observed_, grid);
    if (top_half) o.top = coarse::top_half_icdf(p, grid);
    o.com = coarse::centre_of_mass_height(p);
    o.z_min = std::numeric_limits<double>::infinity();
    o.z_max = -o.z_min;
    for (const auto& x : p.x()) {
        o.z_min = std::min(o.z_min, x.z);
        o.z_max = std::max(o.z_max, x.z);
    }
    return o;
}

LiftPayload DemRealization::lift_input() const {
    auto hc = coarse::heights_and_colours(system_.particles(), observed_);
    return {std::move(hc.heights), std::move(hc.colours)};
}

std::pair<std::size_t, std::size_t> DemRealization::lift_output_sizes() const {
    return {0, system_.particles().size()};
}

void DemRealization::apply_lift(const LiftPayload& lifted) {
    coarse::apply_colours(system_, lifted.bytes, observed_, other_);
}

void DemRealization::after_sample(long samples_taken) {
    if (vtk_ && samples_taken % output_.vtk_every == 0) vtk_->write(system_);
    if (thermo_ && samples_taken % output_.thermo_every == 0) thermo_->write(system_);
}

LiftOutcome ColourLifter::lift(const Eigen::VectorXd& target, const LiftPayload& input,
                               const coarse::ProbabilityGrid& grid, RandomStream& rng) const {
    coarse::LiftResult r = coarse::lift_colours(target, input.reals, input.bytes, grid, rng);
    LiftOutcome out;
    out.changed = static_cast<long>(r.n_changed);
    out.max_deviation = r.max_deviation;
    out.message = r.message;
    out.payload.bytes = std::move(r.colours);
    return out;
}

}  // namespace efdem::mpi_driver
