#pragma once
/// \file
/// CsvRecorder: `<prefix>_mean_icdf.csv` (time and the mean ICDF nodes, one row per sample) and,
/// in cpi mode, `<prefix>_cpi_steps.csv` (one row per coarse step), as CSV that
/// `pandas.read_csv(file)` reads as it is: the first line names the columns, no comment lines.
/// What the files are (efdem version, scene, mode, realizations, observed species, every
/// column with its unit) and how the run ended (`end_status`: "running" until it ends) are in
/// the sidecar `<prefix>_csv_meta.json`, rewritten whole (tmp + rename) at the start and end.

#include <cstdio>
#include <filesystem>

#include "mpi_driver/output/run_recorder.hpp"

namespace efdem::mpi_driver {

class CsvRecorder final : public RunRecorder {
  public:
    /// `resume`: append to the files a restart put back (no headers written); the sidecar is
    /// rewritten (end_status "running" again).
    CsvRecorder(const std::filesystem::path& directory, const std::string& prefix,
                const RunProvenance& provenance, bool resume = false);
    ~CsvRecorder() override;
    CsvRecorder(const CsvRecorder&) = delete;
    CsvRecorder& operator=(const CsvRecorder&) = delete;

    void sample(const SampleRecord& s) override;
    void coarse_step(const coarse::ProjectiveStepRecord& step, const LiftRecord& lift) override;
    /// Writes how the run ended into the sidecar.
    void finish(const RunSummary& summary) override;
    /// Failures are recorded in the run file (/failures, /samples/realizations_used); the CSV
    /// keeps its columns.
    void failure(const FailureRecord&) override {}
    /// `<prefix>_mean_icdf.csv`, `<prefix>_cpi_steps.csv` in cpi mode, `<prefix>_csv_meta.json`.
    std::vector<std::filesystem::path> files() const override;

  private:
    /// Writes the sidecar: the provenance, `end_status`, and `end` (JSON members after it).
    void write_meta(const std::string& end, const std::string& end_status) const;

    std::filesystem::path icdf_path_;
    std::filesystem::path steps_path_;
    std::filesystem::path meta_path_;
    RunProvenance provenance_;
    std::FILE* icdf_ = nullptr;
    std::FILE* steps_ = nullptr;
};

}  // namespace efdem::mpi_driver
