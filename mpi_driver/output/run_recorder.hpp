#pragma once
/// \file
/// What the root records during a run, and where: RunRecorder is the interface the driver
/// calls (the ensemble sees only its SampleSink part: sample_sink.hpp); HDF5 (one file per run,
/// the complete record) and CSV (the mean ICDF and the coarse steps, for quick scripting)
/// implement it.

#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "coarse/equation_free/projective/projective_integrator.hpp"
#include "coarse/equation_free/steady/steady_run.hpp"
#include "mpi_driver/output/sample_sink.hpp"

namespace efdem::mpi_driver {

/// Totals at the end of a run.
struct RunSummary {
    double simulated_time = 0;  ///< time covered by the ensemble
    double dem_time = 0;        ///< time actually simulated by the DEM (per realization)
    /// Wall time of the run loop (direct or cpi), not of the set-up; a restarted run's counts
    /// the processes it resumed through up to their checkpoints (resumed_wall_seconds).
    double wall_seconds = 0;
    /// Of wall_seconds, the part of the processes before this one (0: not a restart; NaN:
    /// unknown, a checkpoint written before efdem kept it: wall_seconds is then this process's).
    double resumed_wall_seconds = 0;
    /// Root wall time from building the realizations to every rank having built its own: the
    /// settling of the beds, nearly all of it (also on a restart, which builds them again).
    double settling_wall_seconds = 0;
    double total_wall_seconds = 0;  ///< root wall time from start-up to the end of the run
    double particle_steps = 0;      ///< summed over all realizations
    long coarse_steps = 0;
    std::string end_status;  ///< "completed", "interrupted: ...", "failed: ...", or why it stopped
    int stop_signal = 0;     ///< the signal that stopped the run (0: none)
    std::string checkpoint;  ///< a stopped run: the checkpoint written where it stopped (or empty)
    double checkpoint_time = 0;  ///< its time
    double restrict_seconds =
        0;                    ///< root wall time in restriction (observe, gather, average, record)
    double lift_seconds = 0;  ///< root wall time in lifting (gather, compute, scatter, apply)
    /// Adaptive CPI: what the controller did and what more realizations would buy (text lines;
    /// empty otherwise).
    std::string controller;
    /// mode = steady | continuation: the solve did not reach its stopping rule (exit code 3;
    /// the best iterate is in the run file).
    bool unconverged = false;
    /// A steady solve (mode = steady | continuation, or a cpi run's hand-off) was stopped by a
    /// signal: nothing of it can be continued from a checkpoint.
    bool solve_interrupted = false;
};

/// mode = steady | continuation: one iterate of a solve, as it comes.
struct SteadyIterateRecord {
    long solve = 0;        ///< 0: the steady solve or the first branch point; k: the k-th corrector
    long iteration = 0;    ///< Newton step / fixed-point iteration within the solve (0: the start)
    double residual = 0;   ///< |F| (continuation correctors: |G| of the extended system)
    double noise = 0;      ///< the noise norm measured with it
    Eigen::VectorXd x;     ///< the iterate's coarse vector
    double parameter = 0;  ///< continuation: the parameter (scene units); 0 otherwise
    double dem_time = 0;   ///< micro time spent since the warm-up ended (per realization)
};

/// Every record of a run: the ensemble's samples and survived failures (SampleSink), and what
/// the run loops add.
class RunRecorder : public SampleSink {
  public:
    virtual void coarse_step(const coarse::ProjectiveStepRecord& step, const LiftRecord& lift) = 0;
    virtual void finish(const RunSummary& summary) = 0;
    /// mode = steady | continuation (default: not recorded): every iterate as it comes, every
    /// new branch point, and the outcome at the end (also of a solve that did not converge or
    /// was interrupted: what it found, with its best iterate).
    virtual void steady_iterate(const SteadyIterateRecord& it) { (void)it; }
    virtual void branch_point(const coarse::BranchPoint& point) { (void)point; }
    virtual void steady_outcome(const coarse::SteadyRunOutcome& outcome) { (void)outcome; }
    /// The files this recorder writes (a checkpoint stores them whole, a restart puts them back).
    virtual std::vector<std::filesystem::path> files() const = 0;
};

/// Provenance stored with every run.
/// What one reduced unit is in SI, when the scene gives the physical scales (gas_drag's
/// particle_diameter, particle_density and gravity; NaN otherwise: a scene that sets gas_drag.A
/// is dimensionless only). Multiply a reduced value by the unit of its kind.
struct SiUnits {
    double length = std::numeric_limits<double>::quiet_NaN();        ///< d_p [m]
    double time = std::numeric_limits<double>::quiet_NaN();          ///< sqrt(d_p/g) [s]
    double velocity = std::numeric_limits<double>::quiet_NaN();      ///< sqrt(g d_p) [m/s]
    double acceleration = std::numeric_limits<double>::quiet_NaN();  ///< g [m/s^2]
    double density = std::numeric_limits<double>::quiet_NaN();       ///< rho_s [kg/m^3]
    double mass = std::numeric_limits<double>::quiet_NaN();          ///< rho_s d_p^3 [kg]
    double pressure = std::numeric_limits<double>::quiet_NaN();      ///< rho_s g d_p [Pa]
    bool known() const { return std::isfinite(length); }
    /// From d_p [m], rho_s [kg/m^3] and g [m/s^2].
    static SiUnits from(double d_p, double rho_s, double g) {
        SiUnits u;
        u.length = d_p;
        u.time = std::sqrt(d_p / g);
        u.velocity = std::sqrt(g * d_p);
        u.acceleration = g;
        u.density = rho_s;
        u.mass = rho_s * d_p * d_p * d_p;
        u.pressure = rho_s * g * d_p;
        return u;
    }
};

struct RunProvenance {
    std::string scene_file;
    std::string scene_text;
    std::string overrides;   ///< the command-line overrides, space-separated
    std::string parameters;  ///< every parameter as "key = value   [origin]" lines
    std::string mode;
    bool hand_off = false;  ///< cpi.hand_off = steady: a cpi run that ends in a steady solve
    int ranks = 1;
    int realizations = 1;
    int realizations_per_rank = 1;
    std::uint64_t seed = 1;
    Eigen::VectorXd p_grid;
    std::string observed_species;
    /// observe.bed: what the bed quantities' axes are (empty names: not recorded).
    std::vector<std::string> species_names;
    double profile_dz = 0;       ///< phi(z) slab thickness [d_p]
    long profile_slabs = 0;      ///< phi(z) slabs from the floor
    double mixing_layer = 0;     ///< Lacey layer thickness [d_p]
    double weight_per_area = 0;  ///< W / A of realization 0 [rho_s g d_p]
    SiUnits si;                  ///< the reduced units in SI (not known: NaN)
};

}  // namespace efdem::mpi_driver
