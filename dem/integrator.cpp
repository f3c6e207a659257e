#include "dem/integrator.hpp"

namespace efdem::dem {

namespace {
/// v += h F/m and w += h T/I for every particle; with Drift, also x += dt v after the kick.
template <bool Drift>
void kick(Particles& p, double h, double dt) {
    const std::size_t n = p.size();
    [[maybe_unused]] Vec3* x = p.x().data();
    Vec3* v = p.v().data();
    Vec3* w = p.omega().data();
    const Vec3* f = p.force().data();
    const Vec3* t = p.torque().data();
    const double* im = p.inv_mass().data();
    const double* ii = p.inv_inertia().data();
    for (std::size_t i = 0; i < n; ++i) {
        v[i] += f[i] * (h * im[i]);
        if constexpr (Drift) x[i] += v[i] * dt;
        w[i] += t[i] * (h * ii[i]);
    }
}
}  // namespace

void VelocityVerlet::first_half(Particles& p) const {
    kick<true>(p, 0.5 * dt_, dt_);
}

void VelocityVerlet::second_half(Particles& p) const {
    kick<false>(p, 0.5 * dt_, dt_);
}

}  // namespace efdem::dem
