#pragma once
/// \file
/// CsvRecorder: `<prefix>_mean_icdf.csv` (time and the mean ICDF nodes, one row per sample) and,
/// in cpi mode, `<prefix>_cpi_steps.csv` (one row per coarse step). Comment lines start with #.

#include <cstdio>
#include <filesystem>

#include "mpi_driver/output/run_recorder.hpp"

namespace efdem::mpi_driver {

class CsvRecorder final : public RunRecorder {
public:
    /// `resume`: append to the files a restart put back (no headers written).
    CsvRecorder(const std::filesystem::path& directory, const std::string& prefix,
                const RunProvenance& provenance, bool resume = false);
    ~CsvRecorder() override;
    CsvRecorder(const CsvRecorder&) = delete;
    CsvRecorder& operator=(const CsvRecorder&) = delete;

    void sample(const SampleRecord& s) override;
    void coarse_step(const coarse::ProjectiveStepRecord& step, const LiftRecord& lift) override;
    void finish(const RunSummary& summary) override;
    /// Failures are recorded in the run file (/failures, /samples/realizations_used); the CSV
    /// keeps its columns.
    void failure(const FailureRecord&) override {}
    /// `<prefix>_mean_icdf.csv`, and `<prefix>_cpi_steps.csv` in cpi mode.
    std::vector<std::filesystem::path> files() const override;

private:
    std::filesystem::path icdf_path_;
    std::filesystem::path steps_path_;
    std::FILE* icdf_ = nullptr;
    std::FILE* steps_ = nullptr;
};

}  // namespace efdem::mpi_driver
