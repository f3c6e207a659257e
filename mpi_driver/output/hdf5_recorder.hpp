#pragma once
/// \file
/// Hdf5Recorder: the complete record of a run in `<prefix>.h5`, written by the root as the run
/// goes (flushed after every sample and step, so a killed run leaves a readable file).
///
/// Layout (times in sqrt(d_p/g), heights in d_p):
///   /                     attributes: format_version, efdem_version, git_hash, build, date,
///                         mode, ranks, realizations, realizations_per_rank, seed,
///                         observed_species, scene_file, overrides; at the end: end_status,
///                         simulated_time, dem_time, wall_seconds (the run loop only),
///                         settling_wall_seconds (building and settling the beds),
///                         total_wall_seconds (start-up to end, settling included),
///                         particle_steps, coarse_steps,
///                         restrict_seconds, lift_seconds (root wall time in the coarse layer)
///   /scene                the scene text as read;  /parameters  every parameter with its origin
///   /p                    the p-grid (m)
///   /samples/time (n), mean (n x m), variance (n x m), icdf (n x R x m), com (n x R)
///   /samples/top_mean (n x m), compact (n x 4), compact_status (n)
///                         [cpi.observable = compact or observe.compact = true]
///   /cpi/t_start, burst_length, healing, window, dt_requested, dt, period, periods, t_end (n)
///   /cpi/status (text), message (text), slope, x_end, x_projected (n x dim)
///   /cpi/slope_standard_error (n x dim): SE_i = std_r(s_r,i) / sqrt(R) of the slope, from
///                         each realization's own slope over the same window [d_p per
///                         sqrt(d_p/g)]; NaN where unavailable (R = 1, compact observable,
///                         no slope)
///   /cpi/repair_max_adjustment, repair_clipped, repair_non_monotone (n)
///   /cpi/stability_assessed, stability_stable, stability_rate, stability_amplification (n)
///   /cpi/lift_changed (n x R), lift_max_deviation (n x R), lift_message (text, per step)

#include <map>
#include <string>

#include "mpi_driver/output/h5_file.hpp"
#include "mpi_driver/output/run_recorder.hpp"

namespace efdem::mpi_driver {

inline constexpr std::int64_t kRunFileFormatVersion = 1;

class Hdf5Recorder final : public RunRecorder {
public:
    /// Writes `<directory>/<prefix>.h5`. `resume`: continue the existing file (put back by a
    /// restart) instead of creating one.
    Hdf5Recorder(const std::filesystem::path& directory, const std::string& prefix,
                 const RunProvenance& provenance, Eigen::Index coarse_dimension, bool resume = false);
    void sample(const SampleRecord& s) override;
    void coarse_step(const coarse::ProjectiveStepRecord& step, const LiftRecord& lift) override;
    void finish(const RunSummary& summary) override;
    void failure(const FailureRecord& f) override;
    std::vector<std::filesystem::path> files() const override { return {path_}; }

private:
    H5Series& series(const std::string& name, std::vector<hsize_t> row_shape, H5Series::Type type);

    std::filesystem::path path_;
    /// PATH.reserve: space held for finishing the run file on a full disk (finish() frees it
    /// first, so that the end status and the file's metadata can still be written).
    std::filesystem::path reserve_;
    H5File file_;
    int realizations_;
    Eigen::Index m_;
    Eigen::Index dim_;
    std::map<std::string, H5Series> series_;
};

}  // namespace efdem::mpi_driver
