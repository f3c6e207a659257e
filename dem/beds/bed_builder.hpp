#pragma once
/// \file
/// Initial beds (physics.md §5.4): a jittered simple-cubic lattice with exact species counts
/// assigned by random permutation, random velocities, then settling under gravity until the
/// kinetic energy per particle is below a threshold; or a LAMMPS `write_data` sphere file.
/// This file reads the bed's keys (the settling protocol's too) and builds the lattice; the
/// settling runs in dem/settling/settling.hpp, and dem/realization_builder.hpp puts the steps
/// together (build_bed).
///
/// Scene keys (scope `bed`):
///
/// | key                    | meaning                                               | default   |
/// |------------------------|-------------------------------------------------------|-----------|
/// | source                 | `lattice` or `lammps_data`                            | lattice   |
/// | count                  | particles per species (lattice), one per species name;| required  |
/// |                        | at most kMaxRealizationParticles (1e6) in all         |           |
/// | spacing                | lattice spacing target (<= box width); the box is     | 1.07      |
/// |                        | floor(l/spacing) sites per row, spacing l/that        |           |
/// | jitter                 | uniform random displacement +- jitter per coordinate  | 0.03      |
/// | velocity_rms           | rms speed of the initial Gaussian velocities          | 0.2       |
/// | settle                 | settle under gravity before the run                   | true      |
/// | settle.damping         | viscous damping gamma of the second stage [1/time]    | 1.0       |
/// | settle.damped_time     | duration of the damped stage                          | 7.2       |
/// | settle.ke_threshold    | stop when translational KE per particle < this x m_min g d_p | 1e-6 |
/// | settle.max_time        | give up (with a warning) after this much settling     | 100       |
/// | file                   | LAMMPS data file (.gz allowed), for lammps_data       | required  |
/// | layering               | `mixed` (species by random permutation), or           | mixed     |
/// |                        | `light_on_top` / `heavy_on_top` (stratified by        |           |
/// |                        | density: a fully demixed start, e.g. for mixing runs) |           |
/// | permute_species        | reassign species by random permutation (exact counts) | false     |
/// | read                   | lattice: start from the settled beds an earlier run   | none      |
/// |                        | wrote with bed.write (not built, not settled)         |           |
/// | read.shared            | every realization reads the file bed.read names       | false     |
/// |                        | (false: realization r reads realization_file(read, r))|           |
/// | read.velocity_rms      | rms speed of Gaussian velocities added to the read    | 0         |
/// |                        | bed (stream `bed_velocities`): decorrelates a shared  |           |
/// |                        | bed's realizations                                    |           |
///
/// Streams: `packing` (jitter, species permutation), `velocities` (initial velocities),
/// `bed_velocities` (bed.read.velocity_rms).
/// The settling stages: free fall for sqrt(2 H_lattice) + 1 time units (the top layer reaches
/// the bed), the damped stage, then contacts alone until the threshold.

#include <filesystem>
#include <vector>

#include "core/rng.hpp"
#include "dem/particles.hpp"
#include "dem/scene.hpp"

namespace efdem::dem {

/// Most time steps of one settling stage (free fall, damped, undamped up to settle.max_time).
inline constexpr long kMaxSettleSteps = 1'000'000'000;

/// Duration of the free-fall stage of settling: the top of a bed `top` high falls onto the bed
/// (g = 1), plus one time unit. Checked against kMaxSettleSteps when the bed is read.
double settle_free_fall_time(double top);

struct BedSpec {
    enum class Source { lattice, lammps_data } source = Source::lattice;
    std::vector<long> count;
    double spacing = 1.07;
    double jitter = 0.03;
    double velocity_rms = 0.2;
    bool settle = true;
    double settle_damping = 1.0;
    double settle_damped_time = 7.2;
    double settle_ke_threshold = 1e-6;
    double settle_max_time = 100.0;
    std::filesystem::path file;
    enum class Layering { mixed, light_on_top, heavy_on_top } layering = Layering::mixed;
    bool permute_species = false;
    /// bed.read: the settled beds of an earlier run (empty: build the lattice); with
    /// read_shared the one file every realization reads, else the name bed.write was given.
    std::filesystem::path read;
    bool read_shared = false;
    double read_velocity_rms = 0;

    /// The file realization `r` reads with bed.read.
    std::filesystem::path read_file(long r) const;

    static BedSpec from_params(const Params& scope, const DemScene& scene);
};

/// The jittered lattice with exact species counts and random velocities (not settled).
Particles lattice_bed(const BedSpec& bed, const DemScene& scene, const RealizationSpec& spec);

/// Reassigns species by a random permutation of the current labels (counts stay exact).
void permute_species(Particles& p, const SpeciesTable& species, RandomStream& rng);

}  // namespace efdem::dem
