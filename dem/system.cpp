#include "dem/system.hpp"

#include <utility>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "core/contracts.hpp"
#include "core/error.hpp"
#include "dem/effect_registry.hpp"

namespace efdem::dem {

System::System(SpeciesTable species, Domain domain, Particles particles,
               std::vector<std::unique_ptr<Effect>> effects, const SystemOptions& options)
    : species_(std::move(species)),
      domain_(domain),
      particles_(std::move(particles)),
      effects_(std::move(effects)),
      options_(options),
      integrator_(options.dt),
      time_(options.start_time) {
    EFDEM_EXPECTS(options.dt > 0);
    for (const auto& e : effects_) {
        const Needs n = e->needs();
        needs_.neighbor_list |= n.neighbor_list;
        needs_.contact_history |= n.contact_history;
        if (n.slab_fields) {
            EFDEM_EXPECTS(!needs_.slab_fields || needs_.slab_thickness == n.slab_thickness);
            needs_.slab_fields = true;
            needs_.slab_thickness = n.slab_thickness;
        }
    }
    // Build only what some effect asked for.
    if (needs_.neighbor_list) neighbors_.emplace(species_.max_diameter(), options_.skin);
    if (needs_.contact_history) history_.emplace(particles_.size());
    if (needs_.slab_fields) slabs_.emplace(needs_.slab_thickness, species_.max_diameter());
    if (neighbors_) {
        neighbors_->build(particles_, domain_, permutation_);
        if (history_) history_->attach(*neighbors_);
    }
    refresh_forces();
}

System::~System() = default;
System::System(System&&) noexcept = default;
System& System::operator=(System&&) noexcept = default;

const Effect* System::find_effect(std::string_view name) const {
    for (const auto& e : effects_)
        if (e->name() == name) return e.get();
    return nullptr;
}

Effect* System::find_effect(std::string_view name) {
    return const_cast<Effect*>(std::as_const(*this).find_effect(name));
}

void System::set_parameter(std::string_view key, double value) {
    const std::optional<EffectParameter> p = find_run_parameter(key);
    EFDEM_EXPECTS(p.has_value());  // the settings accept only run_parameters()
    if (!p) throw std::logic_error(fmt::format("'{}' is not a run parameter of any effect", key));
    Effect* effect = find_effect(p->effect);
    if (!effect)
        throw RuntimeFailure(fmt::format(
            "{} cannot be set: the scene does not list {} in its effects", key, p->effect));
    if (!p->parameter.bounds.contains(value))
        throw RuntimeFailure(fmt::format("{} = {:g} asked for by the coarse solver: outside {}",
                                         key, value, p->parameter.bounds.interval()));
    effect->set_parameter(p->parameter.key, value);
}

ForceContext System::context() {
    return ForceContext{particles_,        domain_,       species_, neighbor_list(),
                        contact_history(), slab_fields(), dt(),     time_};
}

ForceContext System::context() const {
    // Diagnostics read through the same struct; they do not modify the particles.
    auto& self = const_cast<System&>(*this);
    return self.context();
}

void System::compute_forces() {
    // The fields see the positions and (half-step) velocities the forces are evaluated at.
    if (slabs_) slabs_->update(particles_, domain_);
    particles_.zero_forces();
    ForceContext ctx = context();
    for (auto& e : effects_) e->add_forces(ctx);
}

void System::refresh_forces() {
    // Evaluating forces advances the tangential springs by v_t dt; at set-up (and after an
    // outside change of state) that would count one step twice, so the springs are restored.
    std::vector<Vec3> saved_pairs;
    std::vector<Vec3> saved_walls[ContactHistory::kWalls];
    if (history_) {
        saved_pairs.assign(history_->pairs().begin(), history_->pairs().end());
        for (int w = 0; w < ContactHistory::kWalls; ++w)
            saved_walls[w].assign(history_->wall(w).begin(), history_->wall(w).end());
    }
    compute_forces();
    if (history_) {
        std::copy(saved_pairs.begin(), saved_pairs.end(), history_->pairs().begin());
        for (int w = 0; w < ContactHistory::kWalls; ++w)
            std::copy(saved_walls[w].begin(), saved_walls[w].end(), history_->wall(w).begin());
    }
}

void System::update_neighbors() {
    if (!neighbors_ || !neighbors_->needs_rebuild(particles_)) return;
    rebuild_neighbors();
}

void System::rebuild_neighbors() {
    if (!neighbors_) return;
    if (history_) history_->stash(*neighbors_);
    neighbors_->build(particles_, domain_, permutation_);
    if (history_) history_->restore(*neighbors_, permutation_);
}

void System::restore_neighbors(std::span<const Vec3> reference_positions,
                               std::span<const PairHistoryRecord> pair_history) {
    if (!neighbors_) return;
    neighbors_->rebuild_from_reference(particles_, domain_, reference_positions);
    if (history_) history_->import_pairs(*neighbors_, particles_, pair_history);
}

void System::step() {
    integrator_.first_half(particles_);
    update_neighbors();
    compute_forces();
    integrator_.second_half(particles_);
    time_ += dt();
    ++step_;
}

void System::run(long steps) {
    for (long s = 0; s < steps; ++s) {
        step();
        if (options_.health_check_every > 0 && step_ % options_.health_check_every == 0) {
            if (auto problem = health_problem())
                throw RuntimeFailure(fmt::format("realization {}: at t = {:.6g} (step {}): {}",
                                                 options_.realization, time_, step_, *problem),
                                     options_.realization);
        }
    }
}

void System::set_species(std::span<const Index> indices, std::span<const SpeciesId> species) {
    EFDEM_EXPECTS(indices.size() == species.size());
    for (std::size_t k = 0; k < indices.size(); ++k)
        particles_.set_species(indices[k], species[k], species_);
    for (auto& e : effects_) e->species_changed(particles_);
    refresh_forces();
}

void System::rearranged(std::span<const std::uint8_t> moved) {
    EFDEM_EXPECTS(moved.size() == particles_.size());
    // The flags in the order the particles have after the rebuild (permutation_: new -> old).
    std::vector<std::uint8_t> now(moved.begin(), moved.end());
    if (neighbors_) {
        rebuild_neighbors();
        for (std::size_t i = 0; i < now.size(); ++i) now[i] = moved[permutation_[i]];
    }
    if (history_) {
        if (neighbors_) {
            const auto off = neighbors_->offsets();
            const auto ent = neighbors_->entries();
            auto springs = history_->pairs();
            for (std::size_t i = 0; i < now.size(); ++i)
                for (std::uint32_t k = off[i]; k < off[i + 1]; ++k)
                    if (now[i] || now[NeighborList::neighbor(ent[k])]) springs[k] = Vec3{};
        }
        for (int w = 0; w < ContactHistory::kWalls; ++w)
            for (std::size_t i = 0; i < now.size(); ++i)
                if (now[i]) history_->wall(w)[i] = Vec3{};
    }
    refresh_forces();
}

double System::translational_kinetic_energy() const {
    double e = 0;
    const auto v = particles_.v();
    const auto m = particles_.mass();
    for (std::size_t i = 0; i < v.size(); ++i) e += 0.5 * m[i] * norm2(v[i]);
    return e;
}

double System::rotational_kinetic_energy() const {
    double e = 0;
    const auto w = particles_.omega();
    const auto inertia = particles_.inertia();
    for (std::size_t i = 0; i < w.size(); ++i) e += 0.5 * inertia[i] * norm2(w[i]);
    return e;
}

double System::potential_energy() const {
    const ForceContext ctx = context();
    double e = 0;
    for (const auto& eff : effects_) e += eff->potential_energy(ctx);
    return e;
}

ThermoStats System::thermo_stats() const {
    const ForceContext ctx = context();
    ThermoStats s;
    for (const auto& eff : effects_) eff->add_thermo(ctx, s);
    return s;
}

double System::min_time_scale() const {
    double t = std::numeric_limits<double>::infinity();
    for (const auto& e : effects_) t = std::min(t, e->time_scale());
    return t;
}

std::string System::min_time_scale_label() const {
    const Effect* best = nullptr;
    for (const auto& e : effects_)
        if (!best || e->time_scale() < best->time_scale()) best = e.get();
    return best ? best->time_scale_label() : std::string();
}

std::optional<std::string> System::health_problem() const {
    const auto x = particles_.x();
    const auto v = particles_.v();
    const auto tag = particles_.tag();
    const double z_max =
        domain_.has_lid() ? domain_.lid_height : std::numeric_limits<double>::max();
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (!all_finite(x[i]) || !all_finite(v[i]))
            return fmt::format("particle {} has a non-finite position or velocity", tag[i]);
        if (x[i].z < -particles_.radius()[i] || x[i].z > z_max)
            return fmt::format("particle {} left the domain (z = {:.6g})", tag[i], x[i].z);
    }
    const ThermoStats s = thermo_stats();
    if (s.max_overlap > options_.max_overlap_fraction)
        return fmt::format(
            "an overlap of {:.3g} diameters exceeds the limit {:.3g} (watchdog.max_overlap), "
            "particle {} with {}: contacts are too soft for the impact speeds or the "
            "time step is too large",
            s.max_overlap, options_.max_overlap_fraction, s.max_overlap_tag,
            s.max_overlap_partner < 0 ? std::string("a wall")
                                      : fmt::format("particle {}", s.max_overlap_partner));
    return std::nullopt;
}

}  // namespace efdem::dem
