#pragma once
/// \file
/// System: one DEM realization. Owns its particles, species, domain, effects, integrator and
/// whatever the effects need (neighbour list, contact history, slab fields), and nothing else.
///
/// \code
/// System sys(species, domain, std::move(particles), std::move(effects), {.dt = 1e-4});
/// sys.run(1000);                       // 1000 velocity-Verlet steps
/// double ke = sys.kinetic_energy();
/// \endcode

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "dem/contact/contact_history.hpp"
#include "dem/domain.hpp"
#include "dem/effect.hpp"
#include "dem/gas/slab_fields.hpp"
#include "dem/integrator.hpp"
#include "dem/neighbor_list.hpp"
#include "dem/particles.hpp"
#include "dem/species.hpp"

namespace efdem::dem {

struct SystemOptions {
    double dt = 1e-4;         ///< time step [sqrt(d_p/g)]
    double skin = 0.1;        ///< neighbour-list skin [d_p]
    double start_time = 0.0;  ///< simulated time of the initial state
    long realization = -1;    ///< global realization index (for messages), -1 if none
    /// Steps between health checks (non-finite state, particles leaving the domain); 0 = never.
    long health_check_every = 1000;
    /// Largest overlap / diameter accepted by the health check (beyond it the run stops).
    double max_overlap_fraction = 0.1;
};

class System {
  public:
    System(SpeciesTable species, Domain domain, Particles particles,
           std::vector<std::unique_ptr<Effect>> effects, const SystemOptions& options);
    ~System();
    System(System&&) noexcept;
    System& operator=(System&&) noexcept;

    /// Advances `steps` velocity-Verlet steps.
    void run(long steps);
    void step();

    double time() const { return time_; }
    void set_time(double t) { time_ = t; }
    long step_count() const { return step_; }
    double dt() const { return integrator_.dt(); }
    long realization() const { return options_.realization; }

    Particles& particles() { return particles_; }
    const Particles& particles() const { return particles_; }
    const SpeciesTable& species() const { return species_; }
    const Domain& domain() const { return domain_; }
    const NeighborList* neighbor_list() const { return neighbors_ ? &*neighbors_ : nullptr; }
    const ContactHistory* contact_history() const { return history_ ? &*history_ : nullptr; }
    ContactHistory* contact_history() { return history_ ? &*history_ : nullptr; }
    /// The slab fields phi(z), u_s(z) of the current state, or null when no effect needs them.
    const SlabFields* slab_fields() const { return slabs_ ? &*slabs_ : nullptr; }
    const std::vector<std::unique_ptr<Effect>>& effects() const { return effects_; }
    const Effect* find_effect(std::string_view name) const;
    /// The same, to change the effect between steps (e.g. GasDrag::set_superficial_velocity).
    Effect* find_effect(std::string_view name);
    /// Sets a key a run may change between steps ("gas_drag.superficial_velocity": one of
    /// run_parameters(), effect_registry.hpp) to `value`. A RuntimeFailure when the scene does
    /// not list the key's effect or `value` is outside the bounds the scene reads the key with
    /// (the coarse solvers keep to them: this is the last line against a value no bed can be
    /// run at); an unknown key is a contract.
    void set_parameter(std::string_view key, double value);
    /// The union of what the effects need.
    Needs needs() const { return needs_; }

    /// Changes particle species (e.g. by lifting) and refreshes masses and forces. Positions,
    /// velocities, spins and contact histories are untouched.
    void set_species(std::span<const Index> indices, std::span<const SpeciesId> species);

    /// Call after positions (and velocities) were changed from outside by a rearrangement of
    /// the particles (a lift that moves them): rebuilds the neighbour list, forgets every
    /// tangential spring of a particle flagged in `moved` (its pair and wall contacts are new
    /// ones) and refreshes forces. `moved`: one flag per particle, in the
    /// current order.
    void rearranged(std::span<const std::uint8_t> moved);

    /// Recomputes forces and torques for the current state without advancing contact history
    /// (as at set-up); used after the state was changed from outside.
    void refresh_forces();

    double translational_kinetic_energy() const;
    double rotational_kinetic_energy() const;
    double kinetic_energy() const {
        return translational_kinetic_energy() + rotational_kinetic_energy();
    }
    /// Sum of the effects' potential energies (elastic contacts, gravity).
    double potential_energy() const;
    ThermoStats thermo_stats() const;

    /// Shortest time scale any effect must resolve (contact duration), and which pair sets it.
    double min_time_scale() const;
    std::string min_time_scale_label() const;

    /// Empty if healthy, else a message naming the particle and what is wrong.
    std::optional<std::string> health_problem() const;

    /// Rebuilds the neighbour list now (normally it is rebuilt when particles moved skin/2).
    void rebuild_neighbors();
    /// Restores a saved state exactly (checkpoint restart): list built from the reference
    /// positions of the saved last build, so the run continues bit for bit.
    void restore_neighbors(std::span<const Vec3> reference_positions,
                           std::span<const PairHistoryRecord> pair_history);
    void set_step_count(long s) { step_ = s; }

  private:
    ForceContext context();
    ForceContext context() const;
    void compute_forces();
    void update_neighbors();

    SpeciesTable species_;
    Domain domain_;
    Particles particles_;
    std::vector<std::unique_ptr<Effect>> effects_;
    SystemOptions options_;
    VelocityVerlet integrator_;
    Needs needs_;
    std::optional<NeighborList> neighbors_;
    std::optional<ContactHistory> history_;
    std::optional<SlabFields> slabs_;
    std::vector<Index> permutation_;
    double time_ = 0;
    long step_ = 0;
};

}  // namespace efdem::dem
