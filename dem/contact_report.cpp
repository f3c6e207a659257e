#include "dem/contact_report.hpp"

#include <fmt/format.h>

namespace efdem::dem {

void describe_contact_table(const ContactTable& table, EffectReport& r) {
    const ContactSpec& s = table.spec();
    const char* damping = s.damping == DampingModel::restitution ? "restitution (eta_n per pair)"
                          : s.damping == DampingModel::gamma     ? "gamma (one gamma_n, LAMMPS)"
                                                                 : "none";
    r.add("model", fmt::format("normal {}, damping {}, tangential {}",
                               s.normal == NormalModel::hooke ? "hooke" : "hertz", damping,
                               s.tangential == TangentialModel::history ? "history" : "none"));
    r.add("kn", fmt::format("{:g}", s.kn));
    if (s.tangential == TangentialModel::history)
        r.add("kt, mu, eta_t/eta_n", fmt::format("{:g}, {:g}, {:g}", s.kt, s.mu, s.tangential_damping));
    for (const auto& t : table.info())
        r.add(t.label, fmt::format("m_eff {:.6f}  eta_n {:.4f}  gamma_n {:.4f}  e {:.4f}  t_c {:.4e}",
                                   t.m_eff, t.coeffs.eta_n, t.coeffs.eta_n / t.m_eff,
                                   t.restitution, t.contact_time));
}

std::string shortest_contact_label(const ContactTable& table) {
    const PairTypeInfo* best = nullptr;
    for (const auto& t : table.info())
        if (!best || t.contact_time < best->contact_time) best = &t;
    return best ? best->label : std::string();
}

}  // namespace efdem::dem
