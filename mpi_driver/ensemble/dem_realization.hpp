#pragma once
/// \file
/// DemRealization: a dem::System as a member of the ensemble (restriction by species ICDF,
/// lifting by relabelling or by moving particles), with its optional per-realization VTK and
/// thermo output; and ColourLifter, the root's lifting by coarse::lift_colours.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coarse/demixing/colour_lifting.hpp"
#include "dem/beds/bed_observation.hpp"
#include "dem/io/thermo_log.hpp"
#include "dem/io/vtk_writer.hpp"
#include "dem/system.hpp"
#include "mpi_driver/ensemble/realization.hpp"

namespace efdem::mpi_driver {

/// Per-realization output settings (intervals in samples; 0 = none).
struct RealizationOutput {
    std::filesystem::path directory;
    std::string prefix;
    long vtk_every = 0;
    long thermo_every = 0;
    /// Inserted after PREFIX_rNNNN in the per-realization file names: "" for a new run,
    /// "_contNNNNNNNN" (samples done at the checkpoint) for a restarted one, so that the
    /// continuation never writes over the files of the run it continues.
    std::string continuation;
};

/// How a realization is lifted: the cpi.lift_by and cpi.relabel* keys it acts on itself.
struct RealizationLift {
    /// cpi.lift_by = positions: lifts move particles (PositionLifter's payloads) instead of
    /// switching their labels (ColourLifter's).
    bool by_positions = false;
    /// cpi.relabel_velocity = species: a colour lift moves each relabelled particle's vertical
    /// velocity to its new species' local mean (carry_species_velocity).
    bool carry_velocity = false;
    /// cpi.relabel: what lift_input sends after the colours, the values ColourLifter orders the
    /// switches by: light-neighbour counts where the order reads them
    /// (SwitchOrder::reads_light_neighbours), else moving flags.
    coarse::SwitchOrder::By switch_by = coarse::SwitchOrder::By::any;
};

class DemRealization final : public Realization {
  public:
    /// `observed`: the species whose heights make the ICDF (colour 1); `other`: colour 0.
    /// `restarting`: the state will be restored from a checkpoint, so the per-realization
    /// outputs do not record the (discarded) initial state.
    /// `bed`: also measure the bed quantities at every sample (Observation::bed).
    /// `lift`: how it is lifted (RealizationLift).
    DemRealization(dem::System system, dem::SpeciesId observed, dem::SpeciesId other,
                   const RealizationOutput& output, bool restarting = false,
                   std::optional<dem::BedObservationSettings> bed = std::nullopt,
                   RealizationLift lift = {});

    long index() const override { return system_.realization(); }
    double time() const override { return system_.time(); }
    void set_time(double t) override { system_.set_time(t); }
    double dt() const override { return system_.dt(); }
    long particles() const override { return static_cast<long>(system_.particles().size()); }
    /// Runs `steps` DEM steps, asking `stop` every kStopCheckSteps of them, then (when not cut
    /// short) judges whether the bed is still (still_samples()). A cut run is bit for bit the
    /// same steps as an uncut one: System::run is a loop of whole steps.
    bool advance_unless_stopped(long steps, const StopCheck& stop) override;
    /// How often a stop is asked for: 100 steps of a paper-size bed (12,500 spheres) take about
    /// 0.1-0.2 s of one core, well inside Open MPI's 1 s between its SIGTERM and SIGKILL.
    static constexpr long kStopCheckSteps = 100;
    Observation observe(const coarse::ProbabilityGrid& grid, ReferenceNeeds needs) const override;
    /// Colours: heights (reals), colours then one byte per particle (bytes): its light-neighbour
    /// count where RealizationLift::switch_by reads them, else its moving flag. Positions: x, y,
    /// z of every particle then its velocity (reals), colours (bytes).
    LiftPayload lift_input() const override;
    std::pair<std::size_t, std::size_t> lift_output_sizes() const override;
    /// Colours: the new labels. Positions: new positions and velocities (reals), one moved flag
    /// per particle (bytes), then System::rearranged.
    void apply_lift(const LiftPayload& lifted) override;
    /// Still now: every particle's translational speed below kRestSpeed and its acceleration
    /// (force over mass, from the forces of the current state and effects) below
    /// kRestAcceleration. A bed that the gas no longer fluidizes comes to rest exactly (measured
    /// at U_s = 0.19: speeds ~1e-11 sqrt(g d_p), accelerations 7e-9 g, while the slowest moving
    /// bed had 8e-3 and 4e-4) and stays so: its light ICDF then moves by ~1e-13 d_p
    /// (bench/stop_times.py). A bed still whose forces changed (a settled bed when the gas comes
    /// on) is not in balance, so not still. Spins about the contact normal survive at rest and do
    /// not count.
    bool still() const;
    /// At rest: still at the end of the last kRestSamples sample intervals in a row (advance()):
    /// a settling bed's motion can pass below both thresholds for one sample and pick up again
    /// (measured once on the tiny bed without gas: still at one sample, moving for the next five,
    /// then still for good). A lift or a parameter change starts the count again.
    bool at_rest() const override { return still_samples_ >= kRestSamples; }
    long still_samples() const { return still_samples_; }
    static constexpr long kRestSamples = 4;
    /// [sqrt(g d_p)]: four decades below a moving bed, five above one at rest.
    static constexpr double kRestSpeed = 1e-6;
    /// [g]: two decades below a moving bed, two above one at rest.
    static constexpr double kRestAcceleration = 1e-6;
    /// [sqrt(g d_p)]: a particle faster than this moves (lift_input's flags, cpi.relabel): a
    /// tenth of a fluidized bed's typical speeds (0.1-0.2 at U_s = 0.19); 71-88 % of the
    /// particles of the demo bed's realizations late in a slow demixing are slower.
    static constexpr double kMovingSpeed = 1e-2;
    void after_sample(long samples_taken) override;
    /// key: gas_drag.superficial_velocity (the gas_drag effect must be listed).
    void set_parameter(const std::string& key, double value) override;
    RealizationState save_state() const override;
    /// RuntimeFailure if the state does not fit this realization (particle count, tags, history).
    void restore_state(const RealizationState& state) override;

    dem::System& system() { return system_; }
    const dem::System& system() const { return system_; }

  private:
    dem::System system_;
    dem::SpeciesId observed_, other_;
    RealizationOutput output_;
    std::optional<dem::BedObservationSettings> bed_;
    RealizationLift lift_;
    std::optional<dem::VtkSeriesWriter> vtk_;
    std::unique_ptr<dem::ThermoLog> thermo_;
    long still_samples_ = 0;  ///< see still_samples(); part of the checkpoint
};

/// Minimal-change recolouring (physics.md §9) of one realization: payload in = heights (reals)
/// and colours then one byte per particle (DemRealization::lift_input), payload out = colours.
/// `switch_by` (cpi.relabel): which of an interval's particles switch first, read from those
/// bytes (coarse::SwitchOrder); `relabel` (cpi.relabel_nodes): which particles switch
/// (coarse::Relabel).
class ColourLifter final : public Lifter {
  public:
    explicit ColourLifter(coarse::SwitchOrder::By switch_by = coarse::SwitchOrder::By::any,
                          coarse::Relabel relabel = coarse::Relabel::at_nodes)
        : switch_by_(switch_by), relabel_(relabel) {}
    LiftOutcome lift(const Eigen::VectorXd& target, const LiftPayload& input,
                     const coarse::ProbabilityGrid& grid, RandomStream& rng) const override;

  private:
    coarse::SwitchOrder::By switch_by_;
    coarse::Relabel relabel_;
};

}  // namespace efdem::mpi_driver
