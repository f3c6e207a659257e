#include "dem/domain.hpp"

#include "core/param_table.hpp"

namespace efdem::dem {

Domain Domain::from_params(const Params& p) {
    Domain d;
    d.lx = p.get<double>("lx", Bounds::positive());
    d.ly = p.get<double>("ly", Bounds::positive());
    if (p.contains("lid")) d.lid_height = p.get<double>("lid", Bounds::positive());
    return d;
}

}  // namespace efdem::dem
