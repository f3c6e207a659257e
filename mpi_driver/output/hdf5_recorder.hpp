#pragma once
/// \file
/// Hdf5Recorder: the complete record of a run in `<prefix>.h5`, written by the root as the run
/// goes (flushed after every sample and step, so a killed run leaves a readable file).
///
/// Every dataset carries the attributes `units`, `long_name` and `description` and named
/// dimensions (HDF5 dimension scales), from the table of run_file_schema.cpp; every axis is a
/// dataset in the group of the arrays that use it (/samples/time, /samples/p, /bed/time, ...),
/// so that netCDF-4 readers (xarray) open each group; the layout in prose: docs/output.md. The
/// file's attributes: format_version, efdem_version, git_hash, build, date, mode, ranks,
/// realizations, realizations_per_rank, seed, observed_species, scene_file, overrides; at the end:
/// end_status, simulated_time, dem_time, wall_seconds (the run loop only; a restarted run's with
/// the processes it resumed through), resumed_wall_seconds (their part),
/// settling_wall_seconds (building and settling the beds), total_wall_seconds (start-up to
/// end, settling included), particle_steps, coarse_steps, restrict_seconds, lift_seconds.

#include <map>
#include <string>

#include "mpi_driver/output/h5_file.hpp"
#include "mpi_driver/output/run_recorder.hpp"

namespace efdem::mpi_driver {

/// 2: units, descriptions and dimension scales on every dataset; /realization; /bed (observe.bed).
/// 3: every group holds its own axes, dimensions named after them (netCDF-4 readable); long_name;
///    /samples/mean is /samples/mean_icdf, /bed/mean is /bed/ensemble_mean. A restart upgrades a
///    run file of an older format in place (Hdf5Recorder::upgrade).
inline constexpr std::int64_t kRunFileFormatVersion = 3;

class Hdf5Recorder final : public RunRecorder {
  public:
    /// Writes `<directory>/<prefix>.h5`. `resume`: continue the existing file (put back by a
    /// restart) instead of creating one.
    Hdf5Recorder(const std::filesystem::path& directory, const std::string& prefix,
                 const RunProvenance& provenance, Eigen::Index coarse_dimension,
                 bool resume = false);
    void sample(const SampleRecord& s) override;
    void coarse_step(const coarse::ProjectiveStepRecord& step, const LiftRecord& lift) override;
    void finish(const RunSummary& summary) override;
    void failure(const FailureRecord& f) override;
    void steady_iterate(const SteadyIterateRecord& it) override;
    void branch_point(const coarse::BranchPoint& point) override;
    void steady_outcome(const coarse::SteadyRunOutcome& outcome) override;
    std::vector<std::filesystem::path> files() const override { return {path_}; }

  private:
    /// The run file's start: its metadata and axes (a new run), or the attributes of this
    /// part of a restarted one.
    void start(const RunProvenance& p, bool resume);
    H5Series& series(const std::string& name, std::vector<hsize_t> row_shape, H5Series::Type type);
    /// Appends fill rows (NaN, -1, empty text) to `s` until it has `rows` rows: a record an
    /// array did not get keeps the array's rows those of its axis.
    static void fill_rows(H5Series& s, H5Series::Type type, hsize_t rows);
    /// Writes `name`'s units, description and dimension scales (run_file_schema.hpp).
    void document(const std::string& name);
    /// A documented axis dataset 0, 1, ..., n-1 (/realization, /cpi/coarse_node), unless it
    /// exists.
    void index_axis(const std::string& name, Eigen::Index n);
    /// Every group's own axes that are not there yet (a new run: all; a restart: none; an
    /// upgraded file: the copies format 3 added). Growing axes that copy another group's
    /// (/bed/time) take its rows so far.
    void ensure_axes(const RunProvenance& p);
    /// A run file of format 1 or 2 (put back by a restart from an older checkpoint) becomes
    /// format 3 in place: renamed datasets, the groups' own axes, dimension scales laid anew.
    void upgrade(const RunProvenance& p);
    void bed_sample(const SampleRecord& s);

    std::filesystem::path path_;
    /// PATH.reserve: space held for finishing the run file on a full disk (finish() frees it
    /// first, so that the end status and the file's metadata can still be written).
    std::filesystem::path reserve_;
    H5File file_;
    int realizations_;
    Eigen::Index m_;
    Eigen::Index dim_;
    std::map<std::string, H5Series> series_;
    std::size_t species_ = 0, slabs_ = 0;  ///< observe.bed: the axes of /bed
    Eigen::VectorXd initial_height_;       ///< each realization's bed height at the first sample
    double si_pressure_;                   ///< rho_s g d_p [Pa]; NaN: the scene gives no SI scale
};

}  // namespace efdem::mpi_driver
