#pragma once
/// \file
/// ThermoLog: one row per call with the state of a realization (LAMMPS `thermo` style), as CSV
/// that `pandas.read_csv(file)` reads as it is: the first line names the columns, every other
/// line is a row of numbers; no comment lines.
///
/// Columns (units are efdem's reduced units, docs/output.md): `step`; `time`
/// [sqrt(d_p/g)]; `ke_trans_per_particle`, `ke_rot_per_particle` [rho_s g d_p^4];
/// `contacts_per_particle`; `wall_contacts`; `max_overlap` [fraction of the pair's diameter];
/// `neighbor_builds` (neighbour-list builds so far).

#include <cstdio>
#include <filesystem>

#include "dem/system.hpp"

namespace efdem::dem {

class ThermoLog {
  public:
    /// Opens (truncates) `file` and writes the header row; RuntimeFailure if it cannot.
    explicit ThermoLog(const std::filesystem::path& file);
    ~ThermoLog();
    ThermoLog(const ThermoLog&) = delete;
    ThermoLog& operator=(const ThermoLog&) = delete;
    void write(const System& system);

  private:
    std::FILE* file_ = nullptr;
    std::filesystem::path path_;
};

}  // namespace efdem::dem
