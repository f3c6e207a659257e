#include "dem/scene.hpp"

#include <cmath>

#include <fmt/format.h>

#include "dem/effect_registry.hpp"

namespace efdem::dem {

DemScene DemScene::from_params(const Params& root) {
    DemScene s;
    s.dt = root.get<double>("dt", Bounds::closed_open(1e-9, 1.0));
    s.effect_names = root.get<std::vector<std::string>>("effects");
    s.domain = Domain::from_params(root.scope("domain"));
    s.species = SpeciesTable::from_params(root.scope("species"));
    s.skin = root.scope("neighbor").get_or<double>("skin", 0.1, Bounds::open_closed(0.0, 10.0));
    const double cutoff = s.species.max_diameter() + s.skin;
    if (s.domain.lx < 2 * cutoff)
        root.scope("domain").fail("lx",
                                  fmt::format("is narrower than twice the neighbour cutoff "
                                              "(largest diameter + skin = {:g})",
                                              cutoff),
                                  fmt::format(">= {:g}", 2 * cutoff));
    if (s.domain.ly < 2 * cutoff)
        root.scope("domain").fail("ly",
                                  fmt::format("is narrower than twice the neighbour cutoff "
                                              "(largest diameter + skin = {:g})",
                                              cutoff),
                                  fmt::format(">= {:g}", 2 * cutoff));
    return s;
}

std::vector<std::unique_ptr<Effect>> make_effects(const DemScene& scene, const Params& root) {
    const EffectRegistry& registry = effect_registry();
    std::vector<std::unique_ptr<Effect>> out;
    for (std::size_t k = 0; k < scene.effect_names.size(); ++k) {
        const std::string& name = scene.effect_names[k];
        for (std::size_t j = 0; j < k; ++j)
            if (scene.effect_names[j] == name)
                root.fail("effects", "lists '" + quote_for_message(name) + "' twice",
                          "each effect at most once");
        const auto* entry = registry.find(name);
        if (!entry)
            root.fail("effects", "names an unknown effect '" + quote_for_message(name) + "'",
                      "known effects: " + registry.names_joined());
        const EffectSetup setup{root.scope(name), root, scene.species, scene.domain,
                                scene.effect_names};
        out.push_back(entry->make(setup));
    }
    return out;
}

namespace {
/// The velocity-dependent forces (drag): refuses dt > tau (an explicit step longer than the
/// relaxation time overshoots: the tiny test bed at dt = 1e-4 runs at dt = 2.4 tau and leaves
/// the box at 3.7 tau; explicit Euler's own limit on dv/dt = -v/tau is 2 tau); warns above tau/20.
std::string check_relaxation(const DemScene& scene, const Params& root,
                             const std::vector<std::unique_ptr<Effect>>& effects) {
    for (const auto& e : effects) {
        const double tau = e->relaxation_time();
        if (!std::isfinite(tau)) continue;
        if (scene.dt > tau)
            root.fail("dt",
                      fmt::format("exceeds the {}: an explicit step longer than tau amplifies "
                                  "the slip velocity instead of damping it",
                                  e->relaxation_label()),
                      fmt::format("dt <= {:.4g}, or {}", tau, e->relaxation_remedy(scene.dt)));
        if (scene.dt > kWarnDtFraction * tau)
            return fmt::format(
                "dt = {:g} is tau/{:.1f} for the {}; the drag relaxation is "
                "resolved with fewer than 20 steps (recommended dt <= {:.4g})",
                scene.dt, tau / scene.dt, e->relaxation_label(), kWarnDtFraction * tau);
    }
    return {};
}
}  // namespace

std::string check_time_step(const DemScene& scene, const Params& root,
                            const std::vector<std::unique_ptr<Effect>>& effects) {
    const std::string drag_warning = check_relaxation(scene, root, effects);
    const Effect* limiting = nullptr;
    for (const auto& e : effects)
        if (!limiting || e->time_scale() < limiting->time_scale()) limiting = e.get();
    if (!limiting || !std::isfinite(limiting->time_scale())) return drag_warning;
    const double tc = limiting->time_scale();
    const std::string who =
        fmt::format("{} {} contacts", limiting->name(), limiting->time_scale_label());
    if (scene.dt > kRefuseDtFraction * tc)
        root.fail("dt",
                  fmt::format("exceeds t_c/5 = {:.4g} for the {} (contact time t_c = {:.4g}); "
                              "the contacts would not be resolved",
                              kRefuseDtFraction * tc, who, tc),
                  fmt::format("dt <= {:.4g}; recommended dt <= t_c/20 = {:.4g}",
                              kRefuseDtFraction * tc, kWarnDtFraction * tc));
    if (scene.dt > kWarnDtFraction * tc)
        return fmt::format(
            "dt = {:g} is t_c/{:.1f} for the {} (t_c = {:.4g}); contacts are resolved "
            "with fewer than 20 steps, so restitution and overlaps lose accuracy "
            "(recommended dt <= {:.4g})",
            scene.dt, tc / scene.dt, who, tc, kWarnDtFraction * tc);
    return drag_warning;
}

std::string unused_key_hint(const ParamEntry& entry, const std::vector<std::string>& effect_names) {
    const auto dot = entry.key.find('.');
    if (dot == std::string::npos) return {};
    const std::string scope = entry.key.substr(0, dot);
    if (!effect_registry().find(scope)) return {};
    for (const auto& n : effect_names)
        if (n == scope) return {};
    return fmt::format("is '{}' listed in 'effects'?", scope);
}

}  // namespace efdem::dem
