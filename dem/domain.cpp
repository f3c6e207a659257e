#include "dem/domain.hpp"

#include "core/param_table.hpp"

namespace efdem::dem {

Domain Domain::from_params(const Params& p) {
    Domain d;
    const Bounds length = Bounds::open_closed(0.0, kMaxDomainLength);
    d.lx = p.get<double>("lx", length);
    d.ly = p.get<double>("ly", length);
    if (p.contains("lid")) d.lid_height = p.get<double>("lid", length);
    return d;
}

}  // namespace efdem::dem
