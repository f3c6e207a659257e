#pragma once
/// \file
/// ThermoScreen: the ensemble's thermo line, on the screen and in PREFIX_log.txt, in the style
/// of LAMMPS' `thermo` output: a header once, then a line at the first sample at or after every
/// output.thermo_interval, from the first multiple of it (docs/output.md, "Thermo on the screen").
///
/// The line summarises the realizations in the ensemble: mean kinetic energy per particle,
/// mean contacts per particle, the largest overlap of any realization and the mean number of
/// neighbour-list builds so far. Each realization's own numbers are in its PREFIX_rNNNN
/// thermo log (dem::ThermoLog). Samples arrive once they cannot be taken back, so a cpi burst
/// that is redone prints no line twice.

#include <limits>
#include <string>
#include <vector>

#include "mpi_driver/output/run_recorder.hpp"

namespace efdem::mpi_driver {

class ThermoScreen final : public RunRecorder {
  public:
    /// `interval` > 0: time between lines; `realizations`: the ensemble's size (the header).
    ThermoScreen(double interval, int realizations);
    void sample(const SampleRecord& s) override;
    /// What sample() prints for `s` (the header before the first line; "" when no line is due),
    /// moving on to the next interval when it prints.
    std::string lines_for(const SampleRecord& s);
    void coarse_step(const coarse::ProjectiveStepRecord&, const LiftRecord&) override {}
    void failure(const FailureRecord&) override {}
    void finish(const RunSummary&) override {}
    std::vector<std::filesystem::path> files() const override { return {}; }

  private:
    double interval_;
    int realizations_;
    /// Print at the first sample with t >= next_ (NaN: before the first sample).
    double next_ = std::numeric_limits<double>::quiet_NaN();
    bool header_printed_ = false;
};

/// The two header lines (what is averaged, the column names).
std::string thermo_header(double interval, int realizations);
/// One line for `s`; empty when no realization measured its thermo numbers.
std::string thermo_line(const SampleRecord& s);

}  // namespace efdem::mpi_driver
