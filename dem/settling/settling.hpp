#pragma once
/// \file
/// Settling of an initial bed (physics.md §5.4): a second System, built from the effect registry
/// with the scene's own gravity, pair_contact and wall_contact plus a viscous damping, runs the
/// stages of the `bed.settle` protocol. The protocol's keys are read with the bed's
/// (BedSpec, dem/beds/bed_builder.hpp); this room only runs them.
///
/// The stages: free fall for settle_free_fall_time(top) (the top layer reaches the bed), the
/// damped stage (bed.settle.damping for bed.settle.damped_time), then contacts alone in chunks
/// of half a time unit until the translational kinetic energy per particle is below
/// bed.settle.ke_threshold x m_min g d_p, or bed.settle.max_time has passed (a warning).
///
/// Settling a paper-size bed takes minutes: the caller may pass a SettlingReport, called after
/// every chunk of half a time unit (and once at the end) with where the protocol stands
/// (dem/beds/settling_report.hpp, which the realization builder's callers may include). It
/// only reports (dem/ knows no MPI and prints no progress); the caller decides what to show.

#include "dem/beds/bed_builder.hpp"
#include "dem/beds/settling_report.hpp"
#include "dem/particles.hpp"
#include "dem/scene.hpp"

namespace efdem::dem {

/// Settles `particles` with the scene's gravity, pair_contact and wall_contact (InputError on
/// bed.settle if the scene lacks the contact effects). Returns the settled particles, at rest.
Particles settle_bed(Particles particles, const BedSpec& bed, const DemScene& scene,
                     const Params& root, const RealizationSpec& spec,
                     const SettlingReport& report = {});

}  // namespace efdem::dem
