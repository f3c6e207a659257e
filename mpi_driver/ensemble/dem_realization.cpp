#include "mpi_driver/ensemble/dem_realization.hpp"

#include <algorithm>
#include <limits>
#include <unordered_map>

#include <fmt/format.h>

#include "coarse/dem_adapters/apply_colours.hpp"
#include "coarse/dem_adapters/light_neighbours.hpp"
#include "coarse/dem_adapters/realization_observables.hpp"
#include "coarse/dem_adapters/species_velocity.hpp"
#include "coarse/demixing/colour_lifting.hpp"
#include "core/contracts.hpp"
#include "core/error.hpp"
#include "mpi_driver/ensemble/position_lifter.hpp"

namespace efdem::mpi_driver {

DemRealization::DemRealization(dem::System system, dem::SpeciesId observed, dem::SpeciesId other,
                               const RealizationOutput& output, bool restarting,
                               std::optional<dem::BedObservationSettings> bed, RealizationLift lift)
    : system_(std::move(system)),
      observed_(observed),
      other_(other),
      output_(output),
      bed_(bed),
      lift_(lift) {
    const std::string stem =
        fmt::format("{}_r{:04d}{}", output_.prefix, index(), output_.continuation);
    if (output_.vtk_every > 0) vtk_.emplace(output_.directory, stem);
    if (output_.thermo_every > 0)
        thermo_ = std::make_unique<dem::ThermoLog>(output_.directory / (stem + "_thermo.csv"));
    if (!restarting) after_sample(0);
}

Observation DemRealization::observe(const coarse::ProbabilityGrid& grid,
                                    ReferenceNeeds needs) const {
    const dem::Particles& p = system_.particles();
    Observation o;
    o.icdf = coarse::species_icdf(p, observed_, grid);
    if (needs.top_half) o.top = coarse::top_half_icdf(p, grid);
    if (needs.whole_bed) o.whole_bed = coarse::whole_bed_profile(p);
    o.com = coarse::centre_of_mass_height(p);
    o.z_min = std::numeric_limits<double>::infinity();
    o.z_max = -o.z_min;
    for (const auto& x : p.x()) {
        o.z_min = std::min(o.z_min, x.z);
        o.z_max = std::max(o.z_max, x.z);
        o.mean_height += x.z;
    }
    if (!p.x().empty()) {
        o.mean_height /= static_cast<double>(p.x().size());
        o.observed_fraction =
            static_cast<double>(std::count(p.species().begin(), p.species().end(), observed_)) /
            static_cast<double>(p.x().size());
    }
    if (bed_) o.bed = dem::observe_bed(system_, *bed_).pack();
    if (output_.thermo_every > 0) {
        const dem::ThermoStats st = system_.thermo_stats();
        const double n = static_cast<double>(std::max<std::size_t>(1, p.size()));
        o.thermo.ke_per_particle = system_.kinetic_energy() / n;
        o.thermo.contacts_per_particle = static_cast<double>(st.contacts) / n;
        o.thermo.max_overlap = st.max_overlap;
        o.thermo.neighbor_builds =
            system_.neighbor_list() ? static_cast<double>(system_.neighbor_list()->builds()) : 0;
    }
    return o;
}

LiftPayload DemRealization::lift_input() const {
    const dem::Particles& p = system_.particles();
    if (lift_.by_positions) {
        return {pack_positions(p.x(), p.v()), coarse::heights_and_colours(p, observed_).colours};
    }
    auto hc = coarse::heights_and_colours(p, observed_);
    // Then one byte per particle that ColourLifter orders the switches by (cpi.relabel).
    std::vector<std::uint8_t> bytes = std::move(hc.colours);
    if (coarse::SwitchOrder::reads_light_neighbours(lift_.switch_by)) {
        const auto counts = coarse::light_neighbour_counts(p, system_.domain(), observed_);
        bytes.insert(bytes.end(), counts.begin(), counts.end());
    } else {
        bytes.reserve(2 * p.size());
        for (const auto& v : p.v()) bytes.push_back(norm2(v) > kMovingSpeed * kMovingSpeed ? 1 : 0);
    }
    return {std::move(hc.heights), std::move(bytes)};
}

std::pair<std::size_t, std::size_t> DemRealization::lift_output_sizes() const {
    const std::size_t n = system_.particles().size();
    return {lift_.by_positions ? 6 * n : 0, n};
}

void DemRealization::apply_lift(const LiftPayload& lifted) {
    if (lift_.by_positions) {
        dem::Particles& p = system_.particles();
        const std::size_t n = p.size();
        EFDEM_EXPECTS(lifted.reals.size() == 6 * n && lifted.bytes.size() == n);
        const std::vector<Vec3> x = unpack_vectors(lifted.reals, 0, n);
        const std::vector<Vec3> v = unpack_vectors(lifted.reals, n, n);
        std::copy(x.begin(), x.end(), p.x().begin());
        std::copy(v.begin(), v.end(), p.v().begin());
        system_.rearranged(lifted.bytes);
    } else {
        // Before the labels change: the species' means are of the old labels.
        if (lift_.carry_velocity)
            coarse::carry_species_velocity(system_, lifted.bytes, observed_, other_);
        coarse::apply_colours(system_, lifted.bytes, observed_, other_);
    }
    still_samples_ = 0;  // other masses or places: its balance is judged again
}

bool DemRealization::advance_unless_stopped(long steps, const StopCheck& stop) {
    if (!stop) {
        system_.run(steps);
    } else {
        for (long done = 0; done < steps; done += kStopCheckSteps) {
            if (stop()) return false;
            system_.run(std::min(kStopCheckSteps, steps - done));
        }
    }
    still_samples_ = still() ? still_samples_ + 1 : 0;
    return true;
}

bool DemRealization::still() const {
    const dem::Particles& p = system_.particles();
    const auto v = p.v();
    const auto f = p.force();
    const auto inv_mass = p.inv_mass();
    for (std::size_t i = 0; i < v.size(); ++i)
        if (norm2(v[i]) >= kRestSpeed * kRestSpeed ||
            norm2(f[i]) * inv_mass[i] * inv_mass[i] >= kRestAcceleration * kRestAcceleration)
            return false;
    return true;
}

void DemRealization::after_sample(long samples_taken) {
    if (vtk_ && samples_taken % output_.vtk_every == 0) vtk_->write(system_);
    if (thermo_ && samples_taken % output_.thermo_every == 0) thermo_->write(system_);
}

void DemRealization::set_parameter(const std::string& key, double value) {
    system_.set_parameter(key, value);
    still_samples_ = 0;
}

RealizationState DemRealization::save_state() const {
    const dem::Particles& p = system_.particles();
    RealizationState s;
    s.index = index();
    s.time = system_.time();
    s.step = system_.step_count();
    s.still_samples = still_samples_;
    s.x.assign(p.x().begin(), p.x().end());
    s.v.assign(p.v().begin(), p.v().end());
    s.omega.assign(p.omega().begin(), p.omega().end());
    s.force.assign(p.force().begin(), p.force().end());
    s.torque.assign(p.torque().begin(), p.torque().end());
    s.tag.assign(p.tag().begin(), p.tag().end());
    s.species.assign(p.species().begin(), p.species().end());
    if (const dem::NeighborList* list = system_.neighbor_list()) {
        s.reference.assign(list->reference_positions().begin(), list->reference_positions().end());
        if (const dem::ContactHistory* h = system_.contact_history()) {
            s.pairs = h->export_pairs(*list, p);
            for (int w = 0; w < dem::ContactHistory::kWalls; ++w)
                s.wall[w].assign(h->wall(w).begin(), h->wall(w).end());
        }
    }
    return s;
}

void DemRealization::restore_state(const RealizationState& s) {
    dem::Particles& p = system_.particles();
    const std::size_t n = p.size();
    auto refuse = [&](const std::string& what) {
        throw RuntimeFailure(fmt::format("realization {}: {}", index(), what), index());
    };
    if (s.index != index())
        refuse(fmt::format("the checkpoint holds realization {} here", s.index));
    if (s.particles() != n || s.v.size() != n || s.omega.size() != n || s.force.size() != n ||
        s.torque.size() != n || s.tag.size() != n || s.species.size() != n)
        refuse(
            fmt::format("the checkpoint has {} particles, the scene builds {}", s.particles(), n));
    // Storage order: put the particle with tag s.tag[k] at index k.
    std::unordered_map<dem::Tag, dem::Index> where;
    where.reserve(n);
    for (std::size_t i = 0; i < n; ++i) where.emplace(p.tag()[i], static_cast<dem::Index>(i));
    std::vector<dem::Index> new_to_old(n);
    for (std::size_t k = 0; k < n; ++k) {
        const auto it = where.find(s.tag[k]);
        if (it == where.end())
            refuse(fmt::format("particle tag {} is not in the scene's bed", s.tag[k]));
        new_to_old[k] = it->second;
    }
    p.permute(new_to_old);
    still_samples_ = s.still_samples;
    std::copy(s.x.begin(), s.x.end(), p.x().begin());
    std::copy(s.v.begin(), s.v.end(), p.v().begin());
    std::copy(s.omega.begin(), s.omega.end(), p.omega().begin());
    std::vector<dem::Index> all(n);
    std::vector<dem::SpeciesId> species(n);
    for (std::size_t i = 0; i < n; ++i) {
        all[i] = static_cast<dem::Index>(i);
        if (s.species[i] >= system_.species().size())
            refuse(fmt::format("species id {} does not exist", s.species[i]));
        species[i] = s.species[i];
    }
    system_.set_species(all, species);  // radii, masses, inertia (and the effects' caches)
    if (system_.neighbor_list()) {
        if (s.reference.size() != n)
            refuse("the checkpoint has no neighbour-list reference positions");
        system_.restore_neighbors(s.reference, s.pairs);
    }
    if (dem::ContactHistory* h = system_.contact_history())
        for (int w = 0; w < dem::ContactHistory::kWalls; ++w) {
            if (s.wall[w].size() != n) refuse("the checkpoint has no wall contact history");
            std::copy(s.wall[w].begin(), s.wall[w].end(), h->wall(w).begin());
        }
    std::copy(s.force.begin(), s.force.end(), p.force().begin());
    std::copy(s.torque.begin(), s.torque.end(), p.torque().begin());
    system_.set_time(s.time);
    system_.set_step_count(s.step);
}

LiftOutcome ColourLifter::lift(const Eigen::VectorXd& target, const LiftPayload& input,
                               const coarse::ProbabilityGrid& grid, RandomStream& rng) const {
    // input.bytes: the colours, then the bytes to order by (DemRealization::lift_input).
    const std::span<const std::uint8_t> bytes(input.bytes);
    const std::size_t n = input.reals.size();
    EFDEM_EXPECTS(bytes.size() == 2 * n);
    coarse::SwitchOrder order;
    order.by = switch_by_;
    if (switch_by_ != coarse::SwitchOrder::By::any) order.values = bytes.subspan(n);
    coarse::LiftResult r =
        coarse::lift_colours(target, input.reals, bytes.first(n), grid, rng, order, relabel_);
    LiftOutcome out;
    out.changed = static_cast<long>(r.n_changed);
    out.max_deviation = r.max_deviation;
    if (r.applied()) out.deviation = r.achieved_icdf - r.target;
    out.message = r.message;
    out.payload.bytes = std::move(r.colours);
    return out;
}

}  // namespace efdem::mpi_driver
