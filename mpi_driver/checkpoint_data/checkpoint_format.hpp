#pragma once
/// \file
/// What a whole-ensemble checkpoint holds besides the realizations (root-level state), how
/// checkpoint files are named, and the format version. Writing: checkpoint_writer.hpp;
/// reading and validation: checkpoint_reader.hpp. Format (docs/reliability.md):
///
///   /                       attributes format_version, efdem_version, git_hash, build, mode,
///                           realizations, sequence, header_checksum and, written last,
///                           complete = 1 (a file without it was interrupted)
///   /scene, /parameters     the scene text; every parameter as "key = value" lines
///   /driver/reals           t_origin, micro_time, particle_steps, height_lo, height_hi
///   /driver/integers        samples_taken, coarse_steps, without_progress, fell_back,
///                           warmed_up (format 3; earlier formats: 4 values, warmed up)
///   /driver/warmup_done     warm-up time simulated so far (absent in older files: 0)
///   /driver/warmup_tail/    only at a safe point inside a warm-up until steady: the samples its
///                           next drift test reads, t (n) and phase, expansion (n x R, each
///                           where the samples have it)
///   /driver/drift           cpi.finish = steady: the drift test's pool (DriftTest::save();
///                           absent when empty and in older files)
///   /driver/lifting         R x 4: each realization's lifting random stream (xoshiro state)
///   /driver/observable, /driver/recorded   warm starts of the coarse observables
///   /driver/integrator/     the multistep integrator's state by name (format 4; absent for the
///                           single-step integrators): t_end, x_end, curvature_only_front,
///                           hold_kind, hold; history/{tau, slope, se} (n, n x m, n x m);
///                           decay/{ok, rate, ratio, delay, message};
///                           controller/{dt_last, dt_cap, consecutive_rejections};
///                           totals/{attempts, accepted, rejected, direct, dt_taken,
///                           dt_tolerance, dt_tolerance_2r, dt_tolerance_4r, statistical,
///                           truncation}; pool/{tau, slope, se, commitment} (n, n x m,
///                           n x m, n: the slope pool; absent in files written before it);
///                           healing (the next burst's, cpi.healing_auto; absent before it);
///                           lift_reserve (the last lift's error in X, which the next jump
///                           plans for; absent before it); realizations (the last
///                           accepted burst's, cpi.curvature's significance test; absent
///                           before it);
///                           window, window_fast_time2, window_measurements (cpi.window_auto
///                           runs only); member_deviation (R x m, cpi.lift = own runs only);
///                           budget/{variance, truncation, t_last, sigma, last_rate, rate}
///                           (cpi.accuracy runs only: the trajectory's error budget,
///                           trajectory_budget.hpp)
///                           (coarse::MultistepState)
///   /driver/integrator, /driver/integrator_text   formats 2 and 3: the same state as a
///                           positional vector and three lines of text
///   /output/<suffix>        the run's output files (HDF5, CSV) as they were at the checkpoint,
///                           named by what follows output.prefix (".h5", "_mean_icdf.csv", ...)
///   /realizations/...       per realization (global index order): meta (index, step,
///                           particles, pairs), time, checksum, still_samples (since the rest
///                           judgement; absent: 0); per particle (rows offset by
///                           the particle counts) x, v, omega, force, torque, reference,
///                           wall_floor, wall_lid, tag, species; per pair pair_tags, pair_xi

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "coarse/equation_free/projective/projective_run.hpp"
#include "core/error.hpp"
#include "core/rng.hpp"

namespace efdem::mpi_driver {

/// 2 added /driver/integrator and /driver/integrator_text (the multistep integrator's slope
/// history and step-size controller, positional); 3 added warmed_up, /driver/active and
/// /driver/failures; 4 stores the integrator's state as named fields (the group
/// /driver/integrator). Versions 1 to 3 are still read (tests/data/checkpoint_format_*.h5).
inline constexpr std::int64_t kCheckpointFormatVersion = 4;
inline constexpr std::int64_t kOldestReadableCheckpointFormat = 1;

/// The root's state of the coarse layer (EnsembleStepper).
struct StepperState {
    long samples_taken = 0;
    double micro_time = 0;
    double particle_steps = 0;
    double height_lo = 0, height_hi = 0;
    std::vector<RandomStream::State> lifting;  ///< per realization
    std::vector<double> observable;            ///< warm start of the integrator's observable
    std::vector<double> recorded;              ///< warm start of the recorded-only observable
    /// Per realization: 1 in the ensemble, 0 dropped after a failure (empty: all in; format 3).
    std::vector<std::int64_t> active;
    long failures = 0;  ///< realization failures survived so far (ensemble.on_failure)
    /// The run loop's wall time up to this state, summed over every process the run went
    /// through (the root's). NaN: unknown (a steady solve's state, or a checkpoint written before
    /// efdem kept it: /driver/wall_seconds absent).
    double wall_seconds = std::numeric_limits<double>::quiet_NaN();
};

/// The run loop's state: coarse::ProjectiveRunState (t_origin, coarse_steps, without_progress,
/// fell_back); a direct run uses t_origin only.
using DriverState = coarse::ProjectiveRunState;

/// One of the run's output files, saved whole.
struct OutputBlob {
    std::string name;  ///< file name inside output.directory after output.prefix (".h5", ...)
    std::string bytes;
};

/// Everything root-level in a checkpoint.
struct CheckpointHeader {
    std::int64_t format_version = kCheckpointFormatVersion;
    std::string mode;
    long realizations = 0;
    long sequence = 0;  ///< coarse steps (cpi) or samples (direct) done
    std::string scene_text;
    std::string parameters;  ///< "key = value" lines
    StepperState stepper;
    DriverState driver;
    std::vector<OutputBlob> outputs;
    /// Formats 2 and 3 only: the integrator's state as they stored it (a positional vector and
    /// three lines of text), for their checksum; driver.integrator holds it by name
    /// (coarse::MultistepState::from_layout). Empty in a header written now.
    std::vector<double> integrator_layout;
    std::string integrator_layout_text;

    /// FNV-1a over every field: stored with the header, verified on restart.
    std::uint64_t checksum() const;
};

struct RealizationState;

/// Where the EnsembleStepper sends a checkpoint (CheckpointWriter; an interface so that the
/// stepper does not depend on HDF5).
/// Thrown on every rank alike (collectively agreed) when a checkpoint cannot be written.
class CheckpointWriteError : public RuntimeFailure {
  public:
    explicit CheckpointWriteError(const std::string& message) : RuntimeFailure(message) {}
};
/// The CheckpointWriteError of a checkpoint that would not fit on the disk (nothing written).
class CheckpointSpaceError : public CheckpointWriteError {
  public:
    explicit CheckpointSpaceError(const std::string& message) : CheckpointWriteError(message) {}
};

class CheckpointSink {
  public:
    virtual ~CheckpointSink() = default;
    /// Collective; `header` on the root only. Returns the path written.
    virtual std::filesystem::path write(long sequence, const std::vector<RealizationState>& local,
                                        const CheckpointHeader* header) const = 0;
};

/// `<prefix>_ckpt_<sequence, 8 digits>.h5`: names sort in the order they were written.
std::string checkpoint_file_name(const std::string& prefix, long sequence);
/// Whether `name` is a complete checkpoint file name of `prefix` (not a .tmp).
bool is_checkpoint_file_name(const std::string& name, const std::string& prefix);

}  // namespace efdem::mpi_driver
