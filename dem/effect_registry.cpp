#include "dem/effect_registry.hpp"

#include <fmt/format.h>

#include "dem/body_forces/gravity.hpp"
#include "dem/body_forces/viscous_damping.hpp"
#include "dem/contact/pair_contact.hpp"
#include "dem/contact/wall_contact.hpp"
#include "dem/gas/gas_drag.hpp"

namespace efdem::dem {

namespace {
template <class T>
std::unique_ptr<Effect> make(const EffectSetup& s) {
    return std::make_unique<T>(s);
}

// THE table of effects. One row per effect: name (as written in `effects = ...`), factory,
// one-line summary (printed by `efdem --list-effects`), and the keys a run may change between
// steps (the parameters mode = continuation may follow), if any.
const EffectRegistry::Entry kEffects[] = {
    {"gravity", &make<Gravity>, "uniform body force -m g e_z"},
    {"pair_contact", &make<PairContact>,
     "soft-sphere particle-particle contact (hooke|hertz, restitution|gamma, history|none)"},
    {"wall_contact", &make<WallContact>,
     "soft-sphere contact with the floor z = 0 (and the lid, if any); same sub-models"},
    {"gas_drag", &make<GasDrag>,
     "1D locally averaged gas (paper Eq. 1-2): drag + pressure gradient on slab fields",
     GasDrag::run_parameters()},
    {"viscous_damping", &make<ViscousDamping>,
     "F = -gamma m v toward rest; for settling beds, not a physical effect of the bed"},
};
}  // namespace

const EffectRegistry& effect_registry() {
    static const EffectRegistry registry{kEffects};
    return registry;
}

std::vector<EffectParameter> run_parameters() {
    std::vector<EffectParameter> out;
    for (const auto& row : effect_registry().entries())
        for (const RunParameter& p : row.parameters)
            out.push_back({fmt::format("{}.{}", row.name, p.key), row.name, p});
    return out;
}

std::optional<EffectParameter> find_run_parameter(std::string_view key) {
    for (EffectParameter& p : run_parameters())
        if (p.key == key) return p;
    return std::nullopt;
}

}  // namespace efdem::dem
