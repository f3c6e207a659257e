#pragma once
/// \file
/// RunSettings: the run-level keys of a scene (everything that is not one realization's DEM).
/// Times are in sqrt(d_p/g); every time is checked against the time step it must be a multiple
/// of, so that samples fall exactly on DEM steps.
///
/// | key                            | meaning                                             | default |
/// |--------------------------------|-----------------------------------------------------|---------|
/// | mode                           | `direct` (every realization runs the DEM) or `cpi`  | direct  |
/// | seed                           | master seed of every random stream                  | 1       |
/// | ensemble.realizations_per_rank | k: the ensemble has R = P x k realizations          | 1       |
/// | run.duration                   | simulated time to cover (cpi: until reached)        | required|
/// | observe.interval               | time between ICDF samples (a multiple of dt)        | 0.5     |
/// | observe.species                | species whose heights make the ICDF                 | first   |
/// | observe.quantiles              | m: nodes p_i = i/(m+1) of the ICDF                  | 19      |
/// | observe.compact                | also record (A,B,C,D) of y = Q_top - Q_L at every   | false   |
/// |                                | sample (a direct reference for a compact CPI run)   |         |
/// | cpi.observable                 | `icdf` (the ICDF nodes) or `compact` ((A,B,C,D))    | icdf    |
/// | cpi.projection                 | `fixed` (DT = cpi.dt) or `periods` (DT = k T)       | fixed   |
/// | cpi.warmup                     | direct simulation before the first coarse step (the | 0       |
/// |                                | packed start is not on the slow manifold)           |         |
/// | cpi.healing                    | start of each burst left out of the slope           | 10      |
/// | cpi.window                     | estimation window after healing                     | 10      |
/// | cpi.dt                         | projective step DT (projection = fixed)             | 80      |
/// | cpi.periods                    | k in DT = k T (projection = periods)                | 2       |
/// | cpi.max_extension              | most a burst may be lengthened to see 2 periods     | 30      |
/// | cpi.stability                  | `warn`, `halve` or `stop` when DT is flagged        | warn    |
/// | output.directory               | where the run writes (relative: to the scene's      | .       |
/// |                                | folder; on the command line: to the working dir)    |         |
/// | output.prefix                  | file stem of the run's files                        | efdem   |
/// | output.vtk_interval            | time between VTK snapshots per realization (0: none)| 0       |
/// | output.thermo_interval         | time between thermo lines per realization (0: none) | 0       |
/// | checkpoint.interval            | checkpoint every N coarse steps (cpi) or N samples  | 0 (off) |
/// |                                | (direct: N x observe.interval of DEM time)          |         |
/// | checkpoint.keep                | K: how many of the newest checkpoints are kept      | 2       |
/// | checkpoint.directory           | where checkpoints are written                       | output.directory |
/// | restart.allow_physics_change   | accept a restart whose scene changes physics keys   | false   |
/// | debug.checkpoint_delay         | test only: seconds to sleep inside every checkpoint | 0       |
/// |                                | write (between the collective part and the marker)  |         |

#include <cstdint>
#include <filesystem>
#include <string>

#include "coarse/equation_free/stability_monitor.hpp"
#include "core/param_table.hpp"
#include "dem/scene.hpp"

namespace efdem::mpi_driver {

struct ObserveSettings {
    double interval = 0.5;
    long steps_per_sample = 0;  ///< interval / dt
    int quantiles = 19;
    bool compact = false;        ///< record (A,B,C,D) at every sample
    dem::SpeciesId species = 0;  ///< the observed ("light") species
    dem::SpeciesId other = 1;    ///< the other species (colour 0), binary mixtures
};

struct CpiSettings {
    enum class Observable { icdf, compact } observable = Observable::icdf;
    enum class Projection { fixed, periods } projection = Projection::fixed;
    double warmup = 0.0;
    double healing = 10.0;
    double window = 10.0;
    double dt = 80.0;
    int periods = 2;
    double max_extension = 30.0;
    coarse::StabilityPolicy stability = coarse::StabilityPolicy::warn;
};

struct OutputSettings {
    std::filesystem::path directory = ".";
    std::string prefix = "efdem";
    double vtk_interval = 0;
    double thermo_interval = 0;
};

/// Whole-ensemble checkpoints (mpi_driver/checkpoint/checkpoint_writer.hpp). interval = 0: none.
struct CheckpointSettings {
    long interval = 0;            ///< coarse steps (cpi) or samples (direct) between checkpoints
    int keep = 2;                 ///< newest checkpoints kept on disk
    std::filesystem::path directory;
    bool allow_physics_change = false;  ///< restart.allow_physics_change
    double debug_delay = 0;       ///< seconds slept inside each write (kill tests)
    bool enabled() const { return interval > 0; }
};

struct RunSettings {
    enum class Mode { direct, cpi } mode = Mode::direct;
    std::uint64_t seed = 1;
    int realizations_per_rank = 1;
    double duration = 0;
    ObserveSettings observe;
    CpiSettings cpi;
    OutputSettings output;
    CheckpointSettings checkpoint;

    /// Reads and cross-checks the run keys (dt and species come from the DEM scene).
    static RunSettings from_params(const Params& root, const dem::DemScene& scene);
};

/// The number of steps of size `dt` in `duration`, or an InputError on `key` if `duration` is
/// not a whole multiple of `dt` (to 1e-9 relative).
long whole_multiple(const Params& scope, const char* key, double duration, double dt,
                    const std::string& dt_name);

}  // namespace efdem::mpi_driver
