#pragma once
/// \file
/// The table of every effect a scene can list. To add an effect: write
/// dem/effects/<name>.{hpp,cpp}, add ONE row to kEffects in effect_registry.cpp, add the file to
/// dem/CMakeLists.txt, and write docs/effects/<name>.md (see ARCHITECTURE.md).

#include <memory>

#include "core/registry.hpp"
#include "dem/effect.hpp"

namespace efdem::dem {

using EffectRegistry = Registry<Effect, const EffectSetup&>;

/// The registry of all effects (one checked-in table).
const EffectRegistry& effect_registry();

}  // namespace efdem::dem
