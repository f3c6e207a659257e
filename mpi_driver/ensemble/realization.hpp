#pragma once
/// \file
/// Realization: one member of the ensemble as the EnsembleStepper sees it, and Lifter: the
/// root's pure function that computes a realization's lifted state from what it reported.
///
/// A DEM realization (DemRealization) reports particle heights and colours and receives new
/// colours; a toy model used in tests reports and receives its state vector. The stepper moves
/// LiftPayloads between ranks without knowing which.

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "coarse/demixing/ensemble_observable.hpp"  // ReferenceIcdf
#include "coarse/demixing/probability_grid.hpp"
#include "core/error.hpp"
#include "core/rng.hpp"
#include "mpi_driver/checkpoint_data/realization_state.hpp"

namespace efdem::mpi_driver {

/// A realization's state in the numbers of a LAMMPS thermo line (docs/output.md, "Thermo").
struct ThermoNumbers {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    double ke_per_particle = nan;        ///< translational + rotational [rho_s g d_p^4]
    double contacts_per_particle = nan;  ///< touching pairs per particle
    double max_overlap = nan;            ///< largest overlap / the pair's diameter
    double neighbor_builds = nan;        ///< neighbour-list builds so far
};

/// Which reference ICDFs of all particles a sample or a lift asks the realizations for (what
/// the observables' reference() say; the same on every rank).
struct ReferenceNeeds {
    bool top_half = false;
    bool whole_bed = false;
    static ReferenceNeeds of(coarse::ReferenceIcdf kind) {
        return {kind == coarse::ReferenceIcdf::top_half, kind == coarse::ReferenceIcdf::whole_bed};
    }
    ReferenceNeeds operator|(ReferenceNeeds o) const {
        return {top_half || o.top_half, whole_bed || o.whole_bed};
    }
    bool any() const { return top_half || whole_bed; }
    /// As one number, for the root's command broadcast.
    double code() const { return (top_half ? 1.0 : 0.0) + (whole_bed ? 2.0 : 0.0); }
    static ReferenceNeeds from_code(double code) {
        const int c = static_cast<int>(code);
        return {(c & 1) != 0, (c & 2) != 0};
    }
};

/// What a realization reports at one sample (heights in d_p).
struct Observation {
    Eigen::VectorXd icdf;  ///< ICDF of the observed species on the p-grid
    Eigen::VectorXd top;   ///< ICDF of the top half (only when asked for)
    /// The whole bed's profile (coarse/demixing/whole_bed_profile.hpp; only when asked for).
    Eigen::VectorXd whole_bed;
    double com = 0;  ///< centre-of-mass height: the travelling-wave phase signal
    /// Number-weighted mean particle height: the bed's expansion, which (unlike the mass-weighted
    /// centre of mass) demixing of equal spheres leaves unchanged.
    double mean_height = 0;
    double z_min = 0;  ///< lowest particle centre
    double z_max = 0;  ///< highest particle centre
    /// The share of the particles that are of the observed species (NaN: the model has no
    /// species; coarse::EnsembleObservable::set_observed_fraction).
    double observed_fraction = std::numeric_limits<double>::quiet_NaN();
    /// The packed dem::BedObservation (observe.bed = true; empty otherwise).
    std::vector<double> bed;
    /// LAMMPS-style thermo numbers (output.thermo_interval > 0; NaN otherwise).
    ThermoNumbers thermo;
};

/// Data moved for a lift: reals and bytes (either may be empty).
struct LiftPayload {
    std::vector<double> reals;
    std::vector<std::uint8_t> bytes;
};

/// A lift computed by the root for one realization.
struct LiftOutcome {
    LiftPayload payload;
    long changed = 0;          ///< labels (or entries) changed
    double max_deviation = 0;  ///< max |achieved - target| over the p-grid [d_p]
    /// achieved - target at each p-node after the lift as applied [d_p]; empty when nothing was
    /// lifted (rejected target) or the lift failed.
    Eigen::VectorXd deviation;
    std::string message;  ///< non-empty when the target was repaired, clipped or rejected
    /// Non-empty when the lift could not put the realization at its target and left it as it
    /// was (a lift that moves particles whose overlaps did not relax): why. The adaptive
    /// integrator rejects the jump (coarse::CoarseStepper::lift_failure).
    std::string failure;
};

class Realization {
  public:
    virtual ~Realization() = default;
    virtual long index() const = 0;  ///< global realization index
    virtual double time() const = 0;
    virtual void set_time(double t) = 0;
    virtual double dt() const = 0;
    virtual long particles() const = 0;
    /// Asked between chunks of a sample's micro steps; true stops the sample there.
    using StopCheck = std::function<bool()>;
    /// Advances `steps` micro steps; throws RuntimeFailure on a numerical failure.
    void advance(long steps) { advance_unless_stopped(steps, {}); }
    /// The same, asking `stop` (may be empty: never) every few steps, so that a stop signal need
    /// not wait for the end of a long sample (docs/reliability.md, "Stop signals"). Returns false
    /// when `stop` cut the steps short: the realization then stands inside the sample, and the
    /// caller restores a saved state. A model may also ignore `stop` and always return true.
    virtual bool advance_unless_stopped(long steps, const StopCheck& stop) = 0;
    virtual Observation observe(const coarse::ProbabilityGrid& grid,
                                ReferenceNeeds needs) const = 0;
    /// What the root needs to lift this realization.
    virtual LiftPayload lift_input() const = 0;
    /// Sizes (reals, bytes) of the payload apply_lift() expects.
    virtual std::pair<std::size_t, std::size_t> lift_output_sizes() const = 0;
    virtual void apply_lift(const LiftPayload& lifted) = 0;
    /// Whether the realization is at rest: a state its micro model does not leave by itself (a
    /// DEM bed whose gas no longer moves any particle). A lift with cpi.at_rest = hold leaves it
    /// where it is. Default: never at rest.
    virtual bool at_rest() const { return false; }
    /// Called after every sample with the running sample count (per-realization outputs).
    virtual void after_sample(long samples_taken) { (void)samples_taken; }
    /// Sets the scene parameter `key` (a DEM realization: one of dem::run_parameters(),
    /// dem/effect_registry.hpp) to `value` between steps: mode = continuation. Realizations
    /// without it refuse.
    virtual void set_parameter(const std::string& key, double value) {
        (void)value;
        throw RuntimeFailure("this realization type cannot change " + key);
    }
    /// The complete state for a checkpoint, and its exact restoration (checkpoint restart).
    /// Realizations that cannot be checkpointed (test models) keep the defaults, which refuse.
    virtual RealizationState save_state() const {
        throw RuntimeFailure("this realization type cannot be checkpointed");
    }
    virtual void restore_state(const RealizationState& state) {
        (void)state;
        throw RuntimeFailure("this realization type cannot be restored from a checkpoint");
    }
};

/// A rank's realizations, in global index order (EnsembleLayout: k per rank).
using Realizations = std::vector<std::unique_ptr<Realization>>;

/// Root side of lifting: a pure function of the target, the realization's report and its
/// lifting stream, so the root can lift realizations it does not own.
class Lifter {
  public:
    virtual ~Lifter() = default;
    virtual LiftOutcome lift(const Eigen::VectorXd& target, const LiftPayload& input,
                             const coarse::ProbabilityGrid& grid, RandomStream& rng) const = 0;
    /// What LiftOutcome::changed counts, for the step report.
    virtual const char* changed_what() const { return "labels changed"; }
};

}  // namespace efdem::mpi_driver
