#pragma once
/// \file
/// Human-readable reports of a contact table, shared by pair_contact and wall_contact.

#include <string>

#include "dem/contact_model.hpp"
#include "dem/effect.hpp"

namespace efdem::dem {

/// Adds the sub-models and, per pair type, m_eff, eta_n, gamma_n, e and t_c to `r`.
void describe_contact_table(const ContactTable& table, EffectReport& r);
/// The label of the pair type with the shortest contact time.
std::string shortest_contact_label(const ContactTable& table);

}  // namespace efdem::dem
