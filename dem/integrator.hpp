#pragma once
/// \file
/// VelocityVerlet: time integration of translation and rotation (LAMMPS `fix nve/sphere`).
///
///   first_half:  v += (dt/2) F/m;  x += dt v;  w += (dt/2) T/I
///   (forces are then evaluated with the half-step velocities, as in LAMMPS)
///   second_half: v += (dt/2) F/m;  w += (dt/2) T/I
///
/// Second order for conservative forces; velocity-dependent forces (damping, drag) use the
/// half-step velocity, which is first order in them but stable and standard for DEM.

#include "dem/particles.hpp"

namespace efdem::dem {

class VelocityVerlet {
  public:
    explicit VelocityVerlet(double dt) : dt_(dt) {}
    double dt() const { return dt_; }
    void first_half(Particles& p) const;
    void second_half(Particles& p) const;

  private:
    double dt_;
};

}  // namespace efdem::dem
