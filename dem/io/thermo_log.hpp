#pragma once
/// \file
/// ThermoLog: one line per call with the state of a realization (LAMMPS `thermo` style), as a
/// whitespace-separated table with a commented header, for scripts and for eyes.
///
/// Columns: step, time [sqrt(d_p/g)], ke_trans and ke_rot per particle [rho_s g d_p^4],
/// contacts per particle, wall contacts, max overlap [fraction of the pair's diameter],
/// neighbour-list builds so far.

#include <cstdio>
#include <filesystem>

#include "dem/system.hpp"

namespace efdem::dem {

class ThermoLog {
public:
    /// Opens (truncates) `file` and writes the header; RuntimeFailure if it cannot.
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
