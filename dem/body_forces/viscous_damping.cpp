#include "dem/body_forces/viscous_damping.hpp"

#include <fmt/format.h>

namespace efdem::dem {

ViscousDamping::ViscousDamping(const EffectSetup& s)
    : gamma_(s.scope.get<double>("gamma", Bounds::closed(0.0, 1e6))) {}

void ViscousDamping::add_forces(ForceContext& ctx) {
    Vec3* f = ctx.particles.force().data();
    const Vec3* v = ctx.particles.v().data();
    const double* m = ctx.particles.mass().data();
    const std::size_t n = ctx.particles.size();
    for (std::size_t i = 0; i < n; ++i) f[i] -= v[i] * (gamma_ * m[i]);
}

void ViscousDamping::describe(EffectReport& r) const {
    r.add("gamma", fmt::format("{} (relaxation time {})", gamma_, gamma_ > 0 ? 1.0 / gamma_ : 0.0));
}

}  // namespace efdem::dem
