#pragma once
/// \file
/// DemScene: the DEM part of a scene file (time step, box, species, effect list), the effects
/// it lists and the time-step check against them. One realization is built from it by
/// dem/realization_builder.hpp.
///
/// Top-level keys read here: `dt` (required), `effects` (required; the whole list, applied in
/// order), `domain.*`, `species.*`, `neighbor.skin` (default 0.1); `bed.*` is read by
/// dem/beds/bed_builder.hpp.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/param_table.hpp"
#include "dem/domain.hpp"
#include "dem/effect.hpp"
#include "dem/species.hpp"

namespace efdem::dem {

/// Time-step limits relative to the shortest contact duration t_c (issue: stiff contacts).
inline constexpr double kRefuseDtFraction = 1.0 / 5.0;  ///< dt > t_c/5 is refused
inline constexpr double kWarnDtFraction = 1.0 / 20.0;   ///< t_c/20 < dt <= t_c/5 warns

struct DemScene {
    double dt = 0;
    double skin = 0.1;
    Domain domain;
    SpeciesTable species;
    std::vector<std::string> effect_names;

    static DemScene from_params(const Params& root);
};

/// Creates the effects listed in the scene, in order. Unknown names are an InputError that lists
/// the known ones; an effect listed twice is an InputError.
std::vector<std::unique_ptr<Effect>> make_effects(const DemScene& scene, const Params& root);

/// Checks dt against the shortest time scale of the effects: refuses dt > t_c/5 with the computed
/// limit in the message; returns a warning text for t_c/20 < dt <= t_c/5 (empty otherwise).
std::string check_time_step(const DemScene& scene, const Params& root,
                            const std::vector<std::unique_ptr<Effect>>& effects);

/// The hint for an unused scene key: "is 'gas_drag' listed in 'effects'?" when the key belongs
/// to a known effect that is not listed, else "".
std::string unused_key_hint(const ParamEntry& entry, const std::vector<std::string>& effect_names);

/// Everything needed to build one realization (dem/realization_builder.hpp).
struct RealizationSpec {
    std::uint64_t seed = 1;  ///< master seed
    long realization = 0;    ///< global realization index
    bool skip_settling =
        false;  ///< read every key but do not run the settling (efdem --check, a restart)
    /// A restart: the checkpoint overwrites whatever bed is built, so bed.read's files are not
    /// read either (the unsettled lattice is built; a restart needs no bed file).
    bool restart = false;
};

}  // namespace efdem::dem
