#pragma once
/// \file
/// BedTimeSeries: a CSV time series of the bed diagnostics (dem/beds/bed_diagnostics.hpp), one row
/// per call, for plots of Delta P(t), H(t), the species' centre-of-mass heights and for the
/// travelling-wave period (coarse::estimate_period on z_com).
///
/// Format: CSV that `pandas.read_csv(f)` reads as it is: one header row of column names, then
/// comma-separated rows; no comment lines. Columns (efdem's reduced units): step, time
/// [sqrt(d_p/g)], pressure_drop (gas pressure drop across the bed = vertical gas force / area;
/// 0 without gas_drag) [rho_s g d_p], weight_per_area (the fluidized plateau of pressure_drop)
/// [rho_s g d_p], bed_height (99 % of the particle volume lies below it) [d_p], z_com (all)
/// [d_p], z_com_<species> [d_p] for every species, ke_per_particle (translational +
/// rotational) [rho_s g d_p^4].

#include <cstdio>
#include <filesystem>

#include "dem/system.hpp"

namespace efdem::dem {

class BedTimeSeries {
  public:
    /// Opens (truncates) `file` and writes the header, naming `system`'s species; RuntimeFailure
    /// if it cannot.
    BedTimeSeries(const std::filesystem::path& file, const System& system);
    ~BedTimeSeries();
    BedTimeSeries(const BedTimeSeries&) = delete;
    BedTimeSeries& operator=(const BedTimeSeries&) = delete;
    /// Appends one row for the current state of `system` (flushed, so a crash loses nothing).
    void write(const System& system);

  private:
    std::FILE* file_ = nullptr;
};

}  // namespace efdem::dem
