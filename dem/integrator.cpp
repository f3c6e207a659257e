#include "dem/integrator.hpp"

namespace efdem::dem {

void VelocityVerlet::first_half(Particles& p) const {
    const std::size_t n = p.size();
    Vec3* x = p.x().data();
    Vec3* v = p.v().data();
    Vec3* w = p.omega().data();
    const Vec3* f = p.force().data();
    const Vec3* t = p.torque().data();
    const double* im = p.inv_mass().data();
    const double* ii = p.inv_inertia().data();
    const double h = 0.5 * dt_;
    for (std::size_t i = 0; i < n; ++i) {
        v[i] += f[i] * (h * im[i]);
        x[i] += v[i] * dt_;
        w[i] += t[i] * (h * ii[i]);
    }
}

void VelocityVerlet::second_half(Particles& p) const {
    const std::size_t n = p.size();
    Vec3* v = p.v().data();
    Vec3* w = p.omega().data();
    const Vec3* f = p.force().data();
    const Vec3* t = p.torque().data();
    const double* im = p.inv_mass().data();
    const double* ii = p.inv_inertia().data();
    const double h = 0.5 * dt_;
    for (std::size_t i = 0; i < n; ++i) {
        v[i] += f[i] * (h * im[i]);
        w[i] += t[i] * (h * ii[i]);
    }
}

}  // namespace efdem::dem
