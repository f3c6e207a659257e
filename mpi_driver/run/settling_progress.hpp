#pragma once
/// \file
/// The root's progress line while its realizations settle (dem/settling/ only reports, through
/// a dem::SettlingReport): at most one line every `min_seconds` of wall time per realization,
/// naming the stage, the settling time against the stage's end, the steps, and the kinetic
/// energy per particle against the criterion that ends settling; then one line when it is done.
///
///   settling realization 0: damped, t = 3.5 / 12.4, 17500 steps, KE/particle 2.1e-03 (settled
///   below 1.0e-04), 12s settling realization 0: settled at t = 15.5 (77500 steps),
///   KE/particle 8.2e-05 < 1.0e-04, 45s

#include <chrono>

#include "dem/beds/settling_report.hpp"

namespace efdem::mpi_driver {

class SettlingProgressLine {
  public:
    explicit SettlingProgressLine(double min_seconds) : min_seconds_(min_seconds) {}
    /// A report that prints through this object (which must outlive it).
    dem::SettlingReport report();
    void operator()(const dem::SettlingProgress& p);

  private:
    using Clock = std::chrono::steady_clock;
    double min_seconds_;
    long realization_ = -1;  ///< the realization being settled
    Clock::time_point start_{};
    Clock::time_point last_{};
};

}  // namespace efdem::mpi_driver
