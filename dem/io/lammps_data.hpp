#pragma once
/// \file
/// LAMMPS `write_data` files of `atom_style sphere` (gzip-compressed or plain): the reader, so
/// that a bed built by LAMMPS (e.g. tests/data/packed_bed_12500.data.gz) can be loaded, and the
/// writer of the settled beds a run keeps (`bed.write`, read back with `bed.read`).
///
/// Understood: the header counts and box (`xlo xhi`, `ylo yhi`, `zlo zhi`), an optional
/// `Atom Type Labels` section (`type name`, LAMMPS 2022 and later), the `Atoms # sphere`
/// section (`id type diameter density x y z [ix iy iz]`) and an optional `Velocities` section
/// (`id vx vy vz wx wy wz`). LAMMPS type t becomes species t-1; the diameter and density of every
/// atom must match that species (species.density/diameter in the scene), a type label must be
/// that species' name (and, with labels, the header's `atom types` the number of species), and
/// the box must match domain.lx/ly with its origin at 0. Any mismatch or malformed line is an
/// InputError naming the file and line.

#include <filesystem>
#include <string>

#include "dem/domain.hpp"
#include "dem/particles.hpp"
#include "dem/species.hpp"

namespace efdem::dem {

Particles read_lammps_data(const std::filesystem::path& file, const SpeciesTable& species,
                           const Domain& domain);

/// Writes `p` as a LAMMPS data file that LAMMPS' `read_data` (atom_style sphere) and
/// read_lammps_data read: `title` as the first line, the box (z from 0 to the lid, or to the top
/// of the highest sphere without one), `Atom Type Labels` (the species names), `Atoms # sphere`
/// (positions wrapped into the box) and `Velocities`, in tag order, every number with 17
/// significant digits, so that reading the file back gives every double bit for bit. gzip when
/// the name ends in `.gz`. Written to FILE.tmp and renamed, so a crash leaves no half file;
/// RuntimeFailure naming the file if it cannot be written.
void write_lammps_data(const std::filesystem::path& file, const Particles& p,
                       const SpeciesTable& species, const Domain& domain, const std::string& title);

/// The file of realization `realization` for a name given to `bed.write` / `bed.read`: `_rNNNN`
/// (at least four digits, as the VTK and thermo files) before the extension, e.g. beds.data ->
/// beds_r0007.data, beds.data.gz -> beds_r0007.data.gz, beds -> beds_r0007.
std::filesystem::path realization_file(const std::filesystem::path& name, long realization);

}  // namespace efdem::dem
