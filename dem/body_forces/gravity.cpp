#include "dem/body_forces/gravity.hpp"

#include <fmt/format.h>

namespace efdem::dem {

Gravity::Gravity(const EffectSetup& s)
    : g_(s.scope.get_or<double>("g", 1.0, Bounds::closed(0.0, 1e3))) {}

void Gravity::add_forces(ForceContext& ctx) {
    Vec3* f = ctx.particles.force().data();
    const double* m = ctx.particles.mass().data();
    const std::size_t n = ctx.particles.size();
    for (std::size_t i = 0; i < n; ++i) f[i].z -= m[i] * g_;
}

double Gravity::potential_energy(const ForceContext& ctx) const {
    double e = 0;
    const auto x = ctx.particles.x();
    const auto m = ctx.particles.mass();
    for (std::size_t i = 0; i < x.size(); ++i) e += m[i] * g_ * x[i].z;
    return e;
}

void Gravity::describe(EffectReport& r) const {
    r.add("g", fmt::format("{} (downwards)", g_));
}

}  // namespace efdem::dem
