#pragma once
/// \file
/// PairContact: soft-sphere particle-particle contact with sub-models chosen by keyword
/// (dem/contact/contact_model.hpp); the kernel is dem/contact/contact_laws.hpp. Doc:
/// docs/effects/pair_contact.md.

#include "dem/contact/contact_effect.hpp"

namespace efdem::dem {

/**
 * \brief Particle-particle contact forces over the half neighbour list.
 *
 * The sub-model combination (hooke|hertz) x (none|history) is dispatched once per step to a
 * loop instantiated for that combination: no virtual call or branch on the model per pair.
 */
class PairContact final : public ContactEffect {
  public:
    explicit PairContact(const EffectSetup& setup);
    PairContact(const ContactSpec& spec, const SpeciesTable& species);

    std::string_view name() const override { return "pair_contact"; }
    Needs needs() const override;
    void add_forces(ForceContext& ctx) override;
    double potential_energy(const ForceContext& ctx) const override;
    void add_thermo(const ForceContext& ctx, ThermoStats& stats) const override;

  private:
    /// The force loop; inlined into both builds below.
    template <class Normal, class Tangential>
    void loop(ForceContext& ctx) const;
    /// loop() built for AVX2 (core/cpu_dispatch.hpp), chosen at run time when the CPU has it.
    template <class Normal, class Tangential>
    void loop_avx2(ForceContext& ctx) const;

    std::size_t n_species_;
};

}  // namespace efdem::dem
