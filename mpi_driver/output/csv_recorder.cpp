#include "mpi_driver/output/csv_recorder.hpp"

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/version.hpp"

namespace efdem::mpi_driver {

namespace {
std::FILE* open_or_fail(const std::filesystem::path& p, bool append = false) {
    std::FILE* f = std::fopen(p.string().c_str(), append ? "a" : "w");
    if (!f) throw RuntimeFailure("cannot open " + p.string() + " for writing");
    return f;
}
}  // namespace

CsvRecorder::CsvRecorder(const std::filesystem::path& dir, const std::string& prefix,
                         const RunProvenance& prov, bool resume)
    : icdf_path_(dir / (prefix + "_mean_icdf.csv")),
      steps_path_(dir / (prefix + "_cpi_steps.csv")),
      icdf_(open_or_fail(icdf_path_, resume)) {
    if (resume) {
        if (prov.mode == "cpi") steps_ = open_or_fail(steps_path_, true);
        return;
    }
    fmt::print(icdf_, "# efdem {} ({}): ensemble-mean ICDF of '{}' heights [d_p] over R = {} realizations\n",
               version(), git_hash(), prov.observed_species, prov.realizations);
    fmt::print(icdf_, "# scene {}; mode {}; time in sqrt(d_p/g)\n", prov.scene_file, prov.mode);
    fmt::print(icdf_, "time");
    for (Eigen::Index i = 0; i < prov.p_grid.size(); ++i) fmt::print(icdf_, ",Q({:.4g})", prov.p_grid[i]);
    fmt::print(icdf_, "\n");
    std::fflush(icdf_);
    if (prov.mode == "cpi") {
        steps_ = open_or_fail(steps_path_);
        fmt::print(steps_, "# efdem coarse projective steps; times in sqrt(d_p/g)\n"
                           "t_start,burst_length,healing,window,dt_requested,dt,period,status,"
                           "max_repair,clipped,labels_changed,stability_rate,stability_amplification,"
                           "max_slope_se,error_statistical,error_truncation,tolerance,accepted\n");
        std::fflush(steps_);
    }
}

CsvRecorder::~CsvRecorder() {
    if (icdf_) std::fclose(icdf_);
    if (steps_) std::fclose(steps_);
}

void CsvRecorder::sample(const SampleRecord& s) {
    fmt::print(icdf_, "{:.10g}", s.time);
    for (Eigen::Index i = 0; i < s.mean.size(); ++i) fmt::print(icdf_, ",{:.10g}", s.mean[i]);
    fmt::print(icdf_, "\n");
    std::fflush(icdf_);
}

void CsvRecorder::coarse_step(const coarse::ProjectiveStepRecord& r, const LiftRecord& lift) {
    if (!steps_) return;
    long changed = 0;
    for (long c : lift.changed) changed += c;
    const coarse::ControllerRecord& c = r.controller;
    fmt::print(steps_, "{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{},{:.6g},{},{},{:.6g},{:.6g},{:.6g},"
                       "{:.6g},{:.6g},{:.6g},{}\n",
               r.t_start, r.burst_length, r.healing, r.window, r.dt_requested, r.dt, r.period,
               coarse::to_string(r.status), r.repair.max_adjustment, r.repair.n_clipped, changed,
               r.stability.rate, r.stability.amplification, r.max_slope_standard_error(), c.statistical,
               c.truncation, c.tolerance, c.active ? (c.accepted ? "1" : "0") : "");
    std::fflush(steps_);
}

void CsvRecorder::finish(const RunSummary& s) {
    fmt::print(icdf_, "# end: {}; simulated time {:.6g}, DEM time {:.6g}, wall {:.3f} s, {:.4e} particle-steps\n",
               s.end_status, s.simulated_time, s.dem_time, s.wall_seconds, s.particle_steps);
    std::fflush(icdf_);
}

std::vector<std::filesystem::path> CsvRecorder::files() const {
    if (!steps_) return {icdf_path_};
    return {icdf_path_, steps_path_};
}

}  // namespace efdem::mpi_driver
