#include "mpi_driver/output/csv_recorder.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <system_error>

#include "core/error.hpp"
#include "core/io_error.hpp"
#include "core/version.hpp"

namespace efdem::mpi_driver {

namespace {
/// Runs `body` (fmt::print calls on `f`) and flushes; a failed write (a full disk) becomes a
/// RuntimeFailure naming the file.
template <class F>
void written(std::FILE* f, const std::filesystem::path& p, F&& body) {
    try {
        body();
    } catch (const std::system_error& e) {
        throw RuntimeFailure(io_failure_message(p, "the CSV file", e.code().value()));
    }
    flush_or_fail(f, p, "the CSV file");
}

std::FILE* open_or_fail(const std::filesystem::path& p, bool append = false) {
    std::FILE* f = std::fopen(p.string().c_str(), append ? "a" : "w");
    if (!f) throw RuntimeFailure(io_failure_message(p, "the CSV file", errno));
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
    written(icdf_, icdf_path_, [&] {
        fmt::print(icdf_, "# efdem {} ({}): ensemble-mean ICDF of '{}' heights [d_p] over R = {} realizations\n",
                   version(), git_hash(), prov.observed_species, prov.realizations);
        fmt::print(icdf_, "# scene {}; mode {}; time in sqrt(d_p/g)\n", prov.scene_file, prov.mode);
        fmt::print(icdf_, "time");
        for (Eigen::Index i = 0; i < prov.p_grid.size(); ++i) fmt::print(icdf_, ",Q({:.4g})", prov.p_grid[i]);
        fmt::print(icdf_, "\n");
    });
    if (prov.mode == "cpi") {
        steps_ = open_or_fail(steps_path_);
        written(steps_, steps_path_, [&] {
            fmt::print(steps_, "# efdem coarse projective steps; times in sqrt(d_p/g)\n"
                               "t_start,burst_length,healing,window,dt_requested,dt,period,status,"
                               "max_repair,clipped,labels_changed,stability_rate,stability_amplification,"
                               "max_slope_se,error_statistical,error_truncation,tolerance,accepted\n");
        });
    }
}

CsvRecorder::~CsvRecorder() {
    if (icdf_) std::fclose(icdf_);
    if (steps_) std::fclose(steps_);
}

void CsvRecorder::sample(const SampleRecord& s) {
    written(icdf_, icdf_path_, [&] {
        fmt::print(icdf_, "{:.10g}", s.time);
        for (Eigen::Index i = 0; i < s.mean.size(); ++i) fmt::print(icdf_, ",{:.10g}", s.mean[i]);
        fmt::print(icdf_, "\n");
    });
}

void CsvRecorder::coarse_step(const coarse::ProjectiveStepRecord& r, const LiftRecord& lift) {
    if (!steps_) return;
    long changed = 0;
    for (long c : lift.changed) changed += c;
    const coarse::ControllerRecord& c = r.controller;
    written(steps_, steps_path_, [&] {
        fmt::print(steps_,
                   "{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{},{:.6g},{},{},{:.6g},{:.6g},{:.6g},"
                   "{:.6g},{:.6g},{:.6g},{}\n",
                   r.t_start, r.burst_length, r.healing, r.window, r.dt_requested, r.dt, r.period,
                   coarse::to_string(r.status), r.repair.max_adjustment, r.repair.n_clipped, changed,
                   r.stability.rate, r.stability.amplification, r.max_slope_standard_error(), c.statistical,
                   c.truncation, c.tolerance, c.active ? (c.accepted ? "1" : "0") : "");
    });
}

void CsvRecorder::finish(const RunSummary& s) {
    written(icdf_, icdf_path_, [&] {
        fmt::print(icdf_,
                   "# end: {}; simulated time {:.6g}, DEM time {:.6g}, wall {:.3f} s, {:.4e} particle-steps; "
                   "settling wall {:.3f} s, total wall {:.3f} s\n",
                   s.end_status, s.simulated_time, s.dem_time, s.wall_seconds, s.particle_steps,
                   s.settling_wall_seconds, s.total_wall_seconds);
    });
}

std::vector<std::filesystem::path> CsvRecorder::files() const {
    if (!steps_) return {icdf_path_};
    return {icdf_path_, steps_path_};
}

}  // namespace efdem::mpi_driver
