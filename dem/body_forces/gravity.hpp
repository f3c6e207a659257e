#pragma once
/// \file
/// Gravity: a uniform body force m g pointing down (-z). Doc: docs/effects/gravity.md.

#include "dem/effect.hpp"

namespace efdem::dem {

/// F_i = -m_i g e_z.  Key: `gravity.g` (magnitude [g], default 1).
class Gravity final : public Effect {
  public:
    explicit Gravity(const EffectSetup& setup);
    explicit Gravity(double g) : g_(g) {}
    std::string_view name() const override { return "gravity"; }
    void add_forces(ForceContext& ctx) override;
    double potential_energy(const ForceContext& ctx) const override;
    void describe(EffectReport& r) const override;
    double g() const { return g_; }

  private:
    double g_;
};

}  // namespace efdem::dem
