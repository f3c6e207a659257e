#pragma once
/// \file
/// The table of every effect a scene can list. To add an effect: write
/// dem/body_forces/<name>.{hpp,cpp}, add ONE row to kEffects in effect_registry.cpp, add the file
/// to dem/CMakeLists.txt, and write docs/effects/<name>.md (see ARCHITECTURE.md).

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/registry.hpp"
#include "dem/effect.hpp"

namespace efdem::dem {

using EffectRegistry = Registry<Effect, const EffectSetup&>;

/// The registry of all effects (one checked-in table).
const EffectRegistry& effect_registry();

/// A key of an effect that a run may change between steps, by its scene name.
struct EffectParameter {
    std::string key;          ///< as written in a scene: "gas_drag.superficial_velocity"
    std::string_view effect;  ///< "gas_drag"
    RunParameter parameter;   ///< its key in the effect's scope, bounds and summary
};
/// Every such key of every effect, in table order: what continuation.parameter may name.
std::vector<EffectParameter> run_parameters();
/// The one called `key` ("gas_drag.superficial_velocity"), or none.
std::optional<EffectParameter> find_run_parameter(std::string_view key);

}  // namespace efdem::dem
