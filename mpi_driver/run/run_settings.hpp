#pragma once
/// \file
/// RunSettings: the run-level keys of a scene (everything that is not one realization's DEM).
/// Each room reads its own keys and RunSettings gathers them: the coarse layer its cpi.* keys
/// (coarse/equation_free/projective/cpi_settings.hpp; cpi.observable from the table of
/// coarse/demixing/observable_table.hpp), the checkpoint room checkpoint.* and restart.*
/// (mpi_driver/checkpoint_data/checkpoint_settings.hpp). Times are in sqrt(d_p/g); every time is
/// checked against the time step it must be a multiple of, so that samples fall exactly on
/// DEM steps.
///
// clang-format off
/// | key                            | meaning                                             | default |
/// |--------------------------------|-----------------------------------------------------|---------|
/// | mode                           | `direct` (every realization runs the DEM), `cpi`,   | direct  |
/// |                                | `steady` or `continuation` (steady_run_settings.hpp) |         |
/// | seed                           | master seed of every random stream                  | 1       |
/// | ensemble.realizations_per_rank | k: the ensemble has R = P x k realizations          | 1       |
/// | ensemble.on_failure            | abort, drop or replace (cpi) a failing realization   | abort   |
/// |                                | (failure_policy.hpp)                                 |         |
/// | ensemble.max_failures          | failures a drop/replace run survives                 | R/4, >= 1 |
/// | run.duration                   | simulated time to cover (cpi: until reached);       | required|
/// |                                | steady, continuation: most DEM time after the       | 0 (none)|
/// |                                | warm-up (per realization; 0: no limit)              |         |
/// | observe.interval               | time between ICDF samples (a multiple of dt)        | 0.5     |
/// | observe.species                | species whose heights make the ICDF                 | first   |
/// | observe.quantiles              | m: nodes p_i = i/(m+1) of the ICDF                  | 19      |
/// | observe.compact                | also record (A,B,C,D) of y = Q_top - Q_L at every   | false   |
/// |                                | sample (a direct reference for a compact CPI run)   |         |
/// | observe.bed                    | also record the bed quantities at every sample:     | false   |
/// |                                | Delta P, H, species heights, Lacey index, phi(z)    |         |
/// | observe.profile_dz             | slab thickness of the recorded phi(z)                | 1       |
/// | observe.profile_height         | top of the recorded phi(z) (0: 3 x the bed's solid  | 0       |
/// |                                | height, dem::default_profile_slabs)                 |         |
/// | observe.mixing_layer           | layer thickness of the Lacey mixing index           | 2       |
/// | cpi.observable                 | the coarse variable: `icdf` (the ICDF nodes) or     | icdf    |
/// |                                | `compact` ((A,B,C,D)); coarse/demixing/observable_table |     |
/// | cpi.lift                       | `mean`: every realization lifted to the projected X;| mean    |
/// |                                | `members`: each moved by the same increment         |         |
/// | cpi.*                          | the coarse run loop: projective/cpi_settings.hpp    |         |
/// | output.directory               | where the run writes (relative: to the scene's      | .       |
/// |                                | folder; on the command line: to the working dir)    |         |
/// | output.prefix                  | file stem of the run's files                        | efdem   |
/// | output.vtk_interval            | time between VTK snapshots per realization (0: none)| 0       |
/// | output.thermo_interval         | time between thermo lines per realization (0: none) | 0       |
/// | output.overwrite               | a new run may delete and replace the files an       | false   |
/// |                                | earlier run left under output.prefix (output_guard) |         |
/// | bed.write                      | keep each realization's settled bed in a LAMMPS data| none    |
/// |                                | file (NAME_rNNNN.data) for bed.read (setup.cpp)     |         |
/// | checkpoint.*, restart.*        | checkpoint_data/checkpoint_settings.hpp             |         |
/// | debug.fail_realization         | test only: this realization fails ...               | -1      |
/// | debug.fail_time                | ... at the first sample at or after this time       | 0       |
/// | debug.fail_stage               | ... in its DEM steps (sample) or keeping states (keep) | sample |
// clang-format on

#include <cstdint>
#include <filesystem>
#include <string>

#include "coarse/demixing/colour_lifting.hpp"
#include "coarse/equation_free/projective/cpi_settings.hpp"
#include "coarse/equation_free/steady/steady_run_settings.hpp"
#include "core/param_table.hpp"
#include "dem/scene.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_settings.hpp"
#include "mpi_driver/ensemble/failure_policy.hpp"
#include "mpi_driver/ensemble/injected_failure.hpp"

namespace efdem::mpi_driver {

struct ObserveSettings {
    double interval = 0.5;
    long steps_per_sample = 0;  ///< interval / dt
    int quantiles = 19;
    bool compact = false;        ///< record (A,B,C,D) at every sample
    dem::SpeciesId species = 0;  ///< the observed ("light") species
    dem::SpeciesId other = 1;    ///< the other species (colour 0), binary mixtures
    bool bed = false;            ///< record dem::BedObservation at every sample
    double profile_dz = 1.0;     ///< phi(z) slabs [d_p]
    double profile_height = 0;   ///< top of phi(z) [d_p]; 0: dem::default_profile_slabs
    double mixing_layer = 2.0;   ///< Lacey layers [d_p]
};

struct OutputSettings {
    std::filesystem::path directory = ".";
    std::string prefix = "efdem";
    double vtk_interval = 0;
    double thermo_interval = 0;
    bool overwrite = false;  ///< a new run may replace an earlier run's files of the same prefix
    /// bed.write: where each realization's bed is kept once built and settled (empty: not
    /// kept); realization r writes dem::realization_file(bed_write, r). Not by a restart.
    std::filesystem::path bed_write;
};

struct RunSettings {
    enum class Mode { direct, cpi, steady, continuation } mode = Mode::direct;
    std::uint64_t seed = 1;
    int realizations_per_rank = 1;
    double duration = 0;
    ObserveSettings observe;
    /// cpi.observable: a row of coarse::observable_table().
    std::string observable = "icdf";
    /// cpi.lift = members or own: every realization is moved from its own coarse state by the
    /// jump's increment, keeping its offset from the mean (the ensemble stepper's lift); with
    /// own (cpi.multistep.lift_apart) also by DT times its own slope's deviation from the
    /// ensemble slope; `mean` (default): all lifted to X.
    bool lift_members = false;
    /// cpi.at_rest = hold (default where the observable restricts members): a lift leaves the
    /// realizations at rest where they are; lift: every realization is lifted.
    bool hold_at_rest = false;
    /// cpi.relabel: which of each height interval's particles the colour lift relabels first
    /// (ColourLifter). any (default): every candidate alike; moving: the moving ones;
    /// clustered: heavies among lights turn light, lights among heavies turn heavy
    /// (coarse::SwitchOrder::By::light_neighbours); like_lights: new lights drawn with the
    /// lights' neighbourhoods (coarse::SwitchOrder::By::like_lights); keep_clusters: those new
    /// lights, the lone lights removed first (coarse::SwitchOrder::By::keep_clusters).
    coarse::SwitchOrder::By relabel_by = coarse::SwitchOrder::By::any;
    /// cpi.relabel_nodes = matched (default): the colour lift pins each ICDF node's defining
    /// ranks on the particles that meet it best (coarse::Relabel::at_nodes); random: every
    /// switch drawn at random (the fewest switches, the paper's lift).
    bool relabel_at_nodes = true;
    /// cpi.relabel_velocity = species: a relabelled particle's vertical velocity is moved to its
    /// new species' local mean (coarse::carry_species_velocity); kept (default): velocities are
    /// kept (the paper's lift).
    bool carry_species_velocity = false;
    /// cpi.lift_by = positions: lifts exchange particles between heights (PositionLifter), for
    /// beds whose species differ in size; colours (false) switch labels in place.
    bool lift_by_positions = false;
    /// cpi.lift_height_band [d_p]: how far the relaxation after an exchange may move a height.
    double lift_height_band = 0.25;
    /// cpi.lift_resolution [d_p]: the large species observed, how far an observed particle may
    /// lie from its rank's height after the exchange.
    double lift_resolution = 0.1;
    /// ensemble.at_rest = pause (default): a realization at rest is not advanced, only its clock
    /// (direct and cpi runs); simulate: it is advanced like the others.
    bool pause_at_rest = true;
    /// The other cpi.* keys, read by the coarse layer.
    coarse::CpiSettings cpi;
    /// cpi.hand_off = steady: when the CPI run ends (cpi.finish), its state goes to the steady
    /// solver (the steady.* keys, with the hand-off's defaults).
    bool hand_off = false;
    /// mode = steady | continuation, or a hand-off: the steady.* and continuation.* keys.
    coarse::SteadyRunSettings steady;
    OutputSettings output;
    CheckpointSettings checkpoint;
    /// debug.fail_*: a test-only injected failure.
    InjectedFailure injected_failure;
    /// ensemble.on_failure, ensemble.max_failures (max_failures and min_active are completed by
    /// check_ensemble, which knows R).
    FailurePolicy on_failure;

    bool is_cpi() const { return mode == Mode::cpi; }
    /// mode = steady or continuation (the coarse time-tau map, docs/steady_states.md).
    bool is_steady() const { return mode == Mode::steady || mode == Mode::continuation; }
    /// The run solves for a steady state: mode = steady or continuation, or a cpi run that hands
    /// its end to the steady solver.
    bool solves_steady() const { return is_steady() || (is_cpi() && hand_off); }
    /// What asked for the solve, for messages: "mode = steady | continuation" or
    /// "cpi.hand_off = steady".
    std::string steady_solve_key() const;
    /// The run lifts coarse vectors onto the realizations (cpi, steady, continuation).
    bool lifts() const { return mode != Mode::direct; }
    /// "direct", "cpi", "steady" or "continuation".
    const char* mode_name() const;

    /// Reads and cross-checks the run keys (dt and species come from the DEM scene).
    static RunSettings from_params(const Params& root, const dem::DemScene& scene);
    /// What the settings need of the ensemble they run on: an InputError naming the key when
    /// `realizations` (ranks x ensemble.realizations_per_rank) cannot serve them (adaptive CPI
    /// measures its statistical error from the spread of >= 2 realizations' own slopes, on an
    /// observable that restricts each realization).
    void check_ensemble(const Params& root, int realizations);
};

}  // namespace efdem::mpi_driver
