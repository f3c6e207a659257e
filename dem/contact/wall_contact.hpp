#pragma once
/// \file
/// WallContact: soft-sphere contact of particles with the floor (z = 0, the gas distributor)
/// and, when the domain has one, the lid. The wall acts as an infinitely massive sphere at rest
/// (m_eff = m_i, R_eff = r_i), with the same sub-models as pair contact. Doc:
/// docs/effects/wall_contact.md.

#include "dem/contact/contact_effect.hpp"

namespace efdem::dem {

class WallContact final : public ContactEffect {
  public:
    explicit WallContact(const EffectSetup& setup);
    WallContact(const ContactSpec& spec, const SpeciesTable& species);

    std::string_view name() const override { return "wall_contact"; }
    Needs needs() const override;
    void add_forces(ForceContext& ctx) override;
    double potential_energy(const ForceContext& ctx) const override;
    void add_thermo(const ForceContext& ctx, ThermoStats& stats) const override;

  private:
    template <class Normal, class Tangential>
    void loop(ForceContext& ctx, int wall, double z_wall, double normal_sign) const;
};

}  // namespace efdem::dem
