#pragma once
/// \file
/// ContactEffect: what particle-particle and particle-wall contact share: a coefficient table
/// built from the scene's contact sub-models, the contact time it imposes on dt, and its report.

#include <string>

#include "dem/contact/contact_model.hpp"
#include "dem/effect.hpp"

namespace efdem::dem {

class ContactEffect : public Effect {
  public:
    double time_scale() const override { return table_.min_contact_time(); }
    /// The pair type with the shortest contact time ("light-light").
    std::string time_scale_label() const override;
    /// The sub-models and, per pair type, m_eff, eta_n, gamma_n, e and t_c.
    void describe(EffectReport& r) const override;
    const ContactTable& table() const { return table_; }

  protected:
    ContactEffect(const ContactSpec& spec, const SpeciesTable& species,
                  ContactTable::Partner partner)
        : table_(spec, species, partner) {}
    bool has_history() const { return table_.spec().tangential == TangentialModel::history; }

    ContactTable table_;
};

}  // namespace efdem::dem
