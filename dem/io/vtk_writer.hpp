#pragma once
/// \file
/// ParaView output without libvtk: one VTK XML PolyData file (.vtp) per snapshot and a .pvd
/// collection that lists them with their times (open the .pvd in ParaView; render the points as
/// spheres with the `radius` array, colour by `species`).
///
/// Point data: velocity, angular_velocity, radius, mass, species (Int32), tag (Int64).
/// The .pvd is rewritten after each snapshot via a temporary file and a rename, so it is always
/// complete and readable while the run goes on.

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "dem/system.hpp"

namespace efdem::dem {

class VtkSeriesWriter {
public:
    /// Files are `<directory>/<stem>_<index>.vtp` and `<directory>/<stem>.pvd`.
    VtkSeriesWriter(std::filesystem::path directory, std::string stem);
    /// Writes a snapshot of `system` at its current time; RuntimeFailure if the files cannot be
    /// written.
    void write(const System& system);
    const std::filesystem::path& collection() const { return pvd_; }
    std::size_t snapshots() const { return entries_.size(); }

private:
    std::filesystem::path directory_;
    std::string stem_;
    std::filesystem::path pvd_;
    std::vector<std::pair<double, std::string>> entries_;  ///< (time, file name)
};

/// Writes one .vtp file of the particles.
void write_vtp(const std::filesystem::path& file, const Particles& particles);

}  // namespace efdem::dem
