#pragma once
/// \file
/// RecorderList: forwards every record to several recorders (HDF5 and CSV).

#include <memory>
#include <vector>

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
    void finish(const RunSummary& summary) override {
        for (auto& r : recorders_) r->finish(summary);
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
