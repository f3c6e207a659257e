#include "mpi_driver/output/csv_recorder.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <system_error>
#include <utility>

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

/// `text` as a JSON string literal.
std::string json(const std::string& text) {
    std::string out = "\"";
    for (const char c : text) {
        switch (c) {
            case '"':
                out += "\\\"";
                break;
            case '\\':
                out += "\\\\";
                break;
            case '\n':
                out += "\\n";
                break;
            case '\t':
                out += "\\t";
                break;
            default:
                if (static_cast<unsigned char>(c) < 0x20)
                    out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
                else
                    out += c;
        }
    }
    return out + "\"";
}

/// A JSON number; NaN and infinities (which JSON lacks) as null.
std::string json(double x) {
    return std::isfinite(x) ? fmt::format("{:.10g}", x) : "null";
}

/// The columns of the coarse-step CSV, in order, with what each holds and its unit.
constexpr std::pair<const char*, const char*> kStepColumns[] = {
    {"t_start", "micro clock at the start of the burst [sqrt(d_p/g)]"},
    {"burst_length", "time run in the burst, extensions included [sqrt(d_p/g)]"},
    {"healing", "discarded start of the burst [sqrt(d_p/g)]"},
    {"window", "time span the slope was estimated over [sqrt(d_p/g)]"},
    {"dt_requested", "planned projective step DT [sqrt(d_p/g)]"},
    {"dt", "DT taken; 0 when there was no jump [sqrt(d_p/g)]"},
    {"period", "measured period T; nan when the integrator uses none [sqrt(d_p/g)]"},
    {"status", "outcome of the step (text)"},
    {"max_repair", "largest change the monotone repair made to the projected ICDF [d_p]"},
    {"clipped", "ICDF nodes clipped by the repair (count)"},
    {"labels_changed",
     "species labels changed by lifting (particles moved with cpi.lift_by = positions), summed "
     "over the realizations (count)"},
    {"stability_rate", "estimated decay rate lambda [1/sqrt(d_p/g)]"},
    {"stability_amplification", "amplification factor of the step at that rate [-]"},
    {"max_slope_se",
     "largest standard error of the coarse slope [d_p/sqrt(d_p/g)]; NaN with R = 1"},
    {"error_statistical", "adaptive CPI: projection noise of the jump [d_p]; NaN when DT is fixed"},
    {"error_truncation", "adaptive CPI: truncation error estimate [d_p]; NaN when DT is fixed"},
    {"tolerance", "adaptive CPI: cpi.tolerance [d_p]; NaN when DT is fixed"},
    {"accepted", "multistep integrator: 1 jump kept, 0 rejected; empty otherwise"},
};
}  // namespace

CsvRecorder::CsvRecorder(const std::filesystem::path& dir, const std::string& prefix,
                         const RunProvenance& prov, bool resume)
    : icdf_path_(dir / (prefix + "_mean_icdf.csv")),
      steps_path_(dir / (prefix + "_cpi_steps.csv")),
      meta_path_(dir / (prefix + "_csv_meta.json")),
      provenance_(prov),
      icdf_(open_or_fail(icdf_path_, resume)) {
    if (prov.mode == "cpi") steps_ = open_or_fail(steps_path_, resume);
    write_meta("", "running");
    if (resume) return;
    written(icdf_, icdf_path_, [&] {
        fmt::print(icdf_, "time");
        for (Eigen::Index i = 0; i < prov.p_grid.size(); ++i)
            fmt::print(icdf_, ",Q({:.4g})", prov.p_grid[i]);
        fmt::print(icdf_, "\n");
    });
    if (steps_)
        written(steps_, steps_path_, [&] {
            const char* separator = "";
            for (const auto& column : kStepColumns) {
                fmt::print(steps_, "{}{}", separator, column.first);
                separator = ",";
            }
            fmt::print(steps_, "\n");
        });
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
                   "{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{},{:.6g},{},{},{:.6g},"
                   "{:.6g},{:.6g},"
                   "{:.6g},{:.6g},{:.6g},{}\n",
                   r.t_start, r.burst_length, r.healing, r.window, r.dt_requested, r.dt, r.period,
                   coarse::to_string(r.status), r.repair.max_adjustment, r.repair.n_clipped,
                   changed, r.stability.rate, r.stability.amplification,
                   r.max_slope_standard_error(), c.statistical, c.truncation, c.tolerance,
                   c.active ? (c.accepted ? "1" : "0") : "");
    });
}

void CsvRecorder::finish(const RunSummary& s) {
    write_meta(
        fmt::format(",\n  \"simulated_time\": {},\n  \"dem_time\": {},\n  \"wall_seconds\": {},\n"
                    "  \"resumed_wall_seconds\": {},\n"
                    "  \"settling_wall_seconds\": {},\n  \"total_wall_seconds\": {},\n"
                    "  \"particle_steps\": {}",
                    json(s.simulated_time), json(s.dem_time), json(s.wall_seconds),
                    json(s.resumed_wall_seconds), json(s.settling_wall_seconds),
                    json(s.total_wall_seconds), json(s.particle_steps)),
        s.end_status);
}

void CsvRecorder::write_meta(const std::string& end, const std::string& end_status) const {
    const RunProvenance& p = provenance_;
    std::string text = fmt::format(
        "{{\n  \"format\": \"efdem CSV sidecar 1\",\n  \"efdem_version\": {},\n  \"git_hash\": "
        "{},\n"
        "  \"scene_file\": {},\n  \"overrides\": {},\n  \"mode\": {},\n  \"ranks\": {},\n"
        "  \"realizations\": {},\n  \"seed\": {},\n  \"observed_species\": {},\n"
        "  \"units\": {{\"length\": \"d_p\", \"time\": \"sqrt(d_p/g)\"}},\n  \"files\": {{\n",
        json(version()), json(git_hash()), json(p.scene_file), json(p.overrides), json(p.mode),
        p.ranks, p.realizations, p.seed, json(p.observed_species));
    text += fmt::format(
        "    {}: {{\n      \"rows\": \"one per ensemble sample\",\n      \"columns\": {{\n"
        "        \"time\": \"time of the sample [sqrt(d_p/g)]\",\n"
        "        \"Q(p)\": {}\n      }}\n    }}",
        json(icdf_path_.filename().string()),
        json(fmt::format(
            "ensemble-mean inverse CDF of the heights of the '{}' particles at probability p, over "
            "the realizations in the ensemble [d_p]",
            p.observed_species)));
    if (steps_) {
        text += fmt::format(
            ",\n    {}: {{\n      \"rows\": \"one per coarse projective step\",\n"
            "      \"columns\": {{\n",
            json(steps_path_.filename().string()));
        const char* separator = "";
        for (const auto& [name, what] : kStepColumns) {
            text += fmt::format("{}        {}: {}", separator, json(name), json(what));
            separator = ",\n";
        }
        text += "\n      }\n    }";
    }
    text += fmt::format("\n  }},\n  \"end_status\": {}{}\n}}\n", json(end_status), end);
    write_whole_file(meta_path_, text, "the CSV sidecar");
}

std::vector<std::filesystem::path> CsvRecorder::files() const {
    if (!steps_) return {icdf_path_, meta_path_};
    return {icdf_path_, steps_path_, meta_path_};
}

}  // namespace efdem::mpi_driver
