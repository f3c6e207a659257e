#pragma once
/// \file
/// Effect: one physical effect of a scene (gravity, contact, gas drag, ...), chosen by name in
/// the scene's `effects` list and applied in that order every step.
///
/// An effect adds (never overwrites) forces and torques. It declares what it needs, and the
/// System builds and updates only that: no neighbour list without a contact effect, no contact
/// history without tangential history, no slab fields without an effect that reads them.
/// Polymorphism is per effect per step (one virtual call), never per pair.

#include <limits>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/param_table.hpp"
#include "dem/domain.hpp"
#include "dem/particles.hpp"
#include "dem/species.hpp"

namespace efdem::dem {

class NeighborList;
class ContactHistory;
class SlabFields;

/// What an effect needs the System to build and keep up to date.
struct Needs {
    bool neighbor_list = false;
    bool contact_history = false;
    bool slab_fields = false;
    /// Slab thickness dz [d_p] of the slab fields, when slab_fields is set. Every effect that
    /// needs slab fields must ask for the same dz (a contract: one set of slabs per System).
    double slab_thickness = 0.0;
};

/// What an effect may read and write while adding forces (one step of one realization).
struct ForceContext {
    Particles& particles;
    const Domain& domain;
    const SpeciesTable& species;
    const NeighborList* neighbors;  ///< null unless some effect needs it
    ContactHistory* history;        ///< null unless some effect needs it
    const SlabFields* slabs;        ///< null unless some effect needs it; else up to date with
                                    ///< the positions and velocities the forces are evaluated at
    double dt;
    double time;
};

/// Numbers an effect adds to a thermo line (contacts, overlaps).
struct ThermoStats {
    long contacts = 0;             ///< touching particle pairs
    long wall_contacts = 0;        ///< particles touching a wall
    double max_overlap = 0.0;      ///< largest overlap / diameter of the pair
    Tag max_overlap_tag = -1;      ///< a particle of that contact (-1: none)
    Tag max_overlap_partner = -1;  ///< the other particle, or -1 for a wall
};

/// Derived parameters an effect reports for `efdem --check` and the run log.
struct EffectReport {
    std::vector<std::pair<std::string, std::string>> lines;
    void add(std::string key, std::string value) {
        lines.emplace_back(std::move(key), std::move(value));
    }
};

/// What a factory in the effect table receives.
struct EffectSetup {
    Params scope;  ///< the effect's own keys: `<name>.`
    Params root;   ///< the whole scene (for documented fallbacks)
    const SpeciesTable& species;
    const Domain& domain;
    const std::vector<std::string>& effect_names;  ///< the scene's `effects` list
    bool lists(std::string_view name) const {
        for (const auto& n : effect_names)
            if (n == name) return true;
        return false;
    }
};

class Effect {
  public:
    virtual ~Effect() = default;
    virtual std::string_view name() const = 0;
    virtual Needs needs() const { return {}; }
    /// Add this effect's forces and torques for the current state.
    virtual void add_forces(ForceContext& ctx) = 0;
    /// Shortest time scale the integrator must resolve (contact duration), or +inf.
    virtual double time_scale() const { return std::numeric_limits<double>::infinity(); }
    /// Which pair type sets time_scale() ("light-wall"), for messages.
    virtual std::string time_scale_label() const { return {}; }
    /// Shortest relaxation time of a velocity-dependent force (drag), which an explicit step
    /// must resolve, or +inf; relaxation_label() says what sets it, relaxation_remedy() which
    /// key would lengthen it, for messages.
    virtual double relaxation_time() const { return std::numeric_limits<double>::infinity(); }
    virtual std::string relaxation_label() const { return {}; }
    virtual std::string relaxation_remedy(double) const { return {}; }
    /// Potential energy stored by this effect (elastic contacts, gravity) [rho_s g d_p^4].
    virtual double potential_energy(const ForceContext&) const { return 0.0; }
    virtual void add_thermo(const ForceContext&, ThermoStats&) const {}
    virtual void describe(EffectReport&) const {}
    /// Called after particles changed species (lifting): refresh anything derived from masses.
    virtual void species_changed(const Particles&) {}
    /// Sets `key`, one of the RunParameters of this effect's registry row (effect_registry.hpp),
    /// to `value` between steps (mode = continuation). System::set_parameter checks the key and
    /// its bounds first; an effect whose row lists none is never asked (a contract).
    virtual void set_parameter(std::string_view key, double value);
};

}  // namespace efdem::dem
