#pragma once
/// \file
/// Reader for LAMMPS `write_data` files of `atom_style sphere` (gzip-compressed or plain), so
/// that a bed built by LAMMPS (e.g. tests/data/packed_bed_12500.data.gz) can be loaded.
///
/// Understood: the header counts and box (`xlo xhi`, `ylo yhi`, `zlo zhi`), the `Atoms # sphere`
/// section (`id type diameter density x y z [ix iy iz]`) and an optional `Velocities` section
/// (`id vx vy vz wx wy wz`). LAMMPS type t becomes species t-1; the diameter and density of every
/// atom must match that species (species.density/diameter in the scene), and the box must match
/// domain.lx/ly with its origin at 0. Any mismatch or malformed line is an InputError naming the
/// file and line.

#include <filesystem>

#include "dem/domain.hpp"
#include "dem/particles.hpp"
#include "dem/species.hpp"

namespace efdem::dem {

Particles read_lammps_data(const std::filesystem::path& file, const SpeciesTable& species,
                           const Domain& domain);

}  // namespace efdem::dem
