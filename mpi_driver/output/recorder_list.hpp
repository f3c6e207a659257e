#pragma once
/// \file
/// RecorderList: forwards every record to several recorders (HDF5 and CSV).

#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "mpi_driver/output/run_recorder.hpp"

namespace efdem::mpi_driver {

class RecorderList final : public RunRecorder {
  public:
    explicit RecorderList(std::vector<std::unique_ptr<RunRecorder>> recorders)
        : recorders_(std::move(recorders)) {}
    void sample(const SampleRecord& s) override {
        for (auto& r : recorders_) r->sample(s);
    }
    void coarse_step(const coarse::ProjectiveStepRecord& step, const LiftRecord& lift) override {
        for (auto& r : recorders_) r->coarse_step(step, lift);
    }
    void failure(const FailureRecord& f) override {
        for (auto& r : recorders_) r->failure(f);
    }
    void steady_iterate(const SteadyIterateRecord& it) override {
        for (auto& r : recorders_) r->steady_iterate(it);
    }
    void branch_point(const coarse::BranchPoint& point) override {
        for (auto& r : recorders_) r->branch_point(point);
    }
    void steady_outcome(const coarse::SteadyRunOutcome& outcome) override {
        for (auto& r : recorders_) r->steady_outcome(outcome);
    }
    /// Every recorder gets its end even when an earlier one fails (a full disk may refuse a CSV
    /// line and still take the run file's end status, written first from its reserve); then
    /// RuntimeFailure naming what could not be finished.
    void finish(const RunSummary& summary) override {
        std::string failures;
        for (auto& r : recorders_) {
            try {
                r->finish(summary);
            } catch (const std::exception& e) {
                failures += (failures.empty() ? "" : "; ") + std::string(e.what());
            }
        }
        if (!failures.empty()) throw RuntimeFailure(failures);
    }
    std::vector<std::filesystem::path> files() const override {
        std::vector<std::filesystem::path> out;
        for (const auto& r : recorders_)
            for (auto& f : r->files()) out.push_back(std::move(f));
        return out;
    }

  private:
    std::vector<std::unique_ptr<RunRecorder>> recorders_;
};

}  // namespace efdem::mpi_driver
