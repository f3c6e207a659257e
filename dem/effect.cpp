#include "dem/effect.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "core/contracts.hpp"

namespace efdem::dem {

void Effect::set_parameter(std::string_view key, double value) {
    (void)value;
    EFDEM_EXPECTS(!"set_parameter on an effect whose registry row lists no run parameters");
    // Also in a build without contracts: a run must never go on with the physics unchanged.
    throw std::logic_error(fmt::format("effect {} has no run parameter '{}'", name(), key));
}

}  // namespace efdem::dem
