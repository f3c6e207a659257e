#include "dem/contact/contact_effect.hpp"

#include <fmt/format.h>

namespace efdem::dem {

void ContactEffect::describe(EffectReport& r) const {
    const ContactSpec& s = table_.spec();
    const char* damping = s.damping == DampingModel::restitution ? "restitution (eta_n per pair)"
                          : s.damping == DampingModel::gamma     ? "gamma (one gamma_n, LAMMPS)"
                                                                 : "none";
    r.add("model", fmt::format("normal {}, damping {}, tangential {}",
                               with_normal_law(s.normal, [](auto n) { return decltype(n)::kName; }),
                               damping, has_history() ? "history" : "none"));
    r.add("kn", fmt::format("{:g}", s.kn));
    if (has_history())
        r.add("kt, mu, eta_t/eta_n",
              fmt::format("{:g}, {:g}, {:g}", s.kt, s.mu, s.tangential_damping));
    for (const auto& t : table_.info())
        r.add(
            t.label,
            fmt::format("m_eff {:.6f}  eta_n {:.4f}  gamma_n {:.4f}  e {:.4f}  t_c {:.4e}", t.m_eff,
                        t.coeffs.eta_n, t.coeffs.eta_n / t.m_eff, t.restitution, t.contact_time));
}

std::string ContactEffect::time_scale_label() const {
    const PairTypeInfo* best = nullptr;
    for (const auto& t : table_.info())
        if (!best || t.contact_time < best->contact_time) best = &t;
    return best ? best->label : std::string();
}

}  // namespace efdem::dem
