#pragma once
/// \file
/// ViscousDamping: F = -gamma m v, a drag toward rest used to settle packed beds quickly
/// (LAMMPS `fix viscous`). Not a physical effect of the fluidized bed: it is for preparation.

#include "dem/effect.hpp"

namespace efdem::dem {

/// F_i = -gamma m_i v_i.  Key: `viscous_damping.gamma` [1/time], required, >= 0.
class ViscousDamping final : public Effect {
  public:
    explicit ViscousDamping(const EffectSetup& setup);
    explicit ViscousDamping(double gamma) : gamma_(gamma) {}
    std::string_view name() const override { return "viscous_damping"; }
    void add_forces(ForceContext& ctx) override;
    void describe(EffectReport& r) const override;
    /// Changes gamma between runs (the settling protocol switches the damping on and off).
    void set_gamma(double gamma) { gamma_ = gamma; }

  private:
    double gamma_;
};

}  // namespace efdem::dem
