#pragma once
/// \file
/// ParaView output without libvtk: one VTK XML PolyData file (.vtp) per snapshot and a .pvd
/// collection that lists them with their times (open the .pvd in ParaView; the default Surface
/// view shows the particles as points; Glyph (Sphere, scale by `diameter`, factor 1) or Point
/// Gaussian (radius array `radius`) shows them as spheres; colour by `species`).
///
/// A .vtp file (VTK XML, version 1.0, `header_type="UInt64"`, byte order of the machine) holds
/// its arrays as raw binary appended data (`<AppendedData encoding="raw">`, each block
/// prefixed by its UInt64 byte count) and one vertex cell per particle (Verts: connectivity
/// and offsets, Int64), so that every point is a cell a default view draws.
///
/// * Points: `position` (Float64 x 3) [d_p].
/// * Point data: `velocity`, `angular_velocity` (Float64 x 3) [sqrt(g d_p)], [sqrt(g/d_p)];
///   `radius`, `diameter` [d_p], `mass` [rho_s d_p^3] (Float64); `species` (Int32, the index
///   into `species_names`); `tag` (Int64, the permanent particle id).
/// * Field data: `TimeValue` (Float64, 1 tuple) [sqrt(d_p/g)] and `species_names` (String,
///   one tuple per species, in species-index order), which VTK 9's vtkXMLPolyDataReader reads
///   as a vtkStringArray (tests/scripts/test_vtk_client.py).
///
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

/// Writes one .vtp file of `system`'s particles at its current time (via `file`.tmp and a
/// rename); RuntimeFailure if it cannot.
void write_vtp(const std::filesystem::path& file, const System& system);

}  // namespace efdem::dem
