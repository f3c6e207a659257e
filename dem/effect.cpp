#include "dem/effect.hpp"

#include "core/contracts.hpp"

namespace efdem::dem {

void Effect::set_parameter(std::string_view key, double value) {
    (void)key;
    (void)value;
    EFDEM_EXPECTS(!"set_parameter on an effect whose registry row lists no run parameters");
}

}  // namespace efdem::dem
