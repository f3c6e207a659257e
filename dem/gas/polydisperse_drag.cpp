#include "dem/gas/polydisperse_drag.hpp"

#include <algorithm>
#include <cmath>

#include "core/contracts.hpp"
#include "dem/gas/slab_fields.hpp"

namespace efdem::dem {

PolydisperseDrag::PolydisperseDrag(double A, const DragLaw* law, double phi_cap)
    : A_(A), law_(law), phi_cap_(phi_cap) {
    EFDEM_EXPECTS(A > 0.0 && law != nullptr && phi_cap > 0.0 && phi_cap < 1.0);
}

void PolydisperseDrag::coefficients(const SlabFields& slabs, const Particles& p, double U_s) {
    const std::size_t n = slabs.size();
    if (e_.size() < n) {
        inv_d_volume_.resize(n);
        inv_d_momentum_.resize(n);
        e_.resize(n);
        b_.resize(n);
        q_.resize(n);
        total_.resize(n);
    }
    std::fill_n(inv_d_volume_.begin(), n, 0.0);
    std::fill_n(inv_d_momentum_.begin(), n, Vec3{});
    const Vec3* v = p.v().data();
    const double* radius = p.radius().data();
    for (std::size_t i = 0; i < p.size(); ++i) {
        const double inv_d = 0.5 / radius[i];
        const auto w = slabs.weights(i);
        const std::uint32_t j0 = slabs.first_slab(i);
        for (std::size_t k = 0; k < w.size(); ++k) {
            inv_d_volume_[j0 + k] += w[k] * inv_d;
            inv_d_momentum_[j0 + k] += v[i] * (w[k] * inv_d);
        }
    }
    const auto phi = slabs.phi();
    const auto u_s = slabs.solid_velocity();
    const auto volume = slabs.solid_volume();
    const double inv_slab = 1.0 / slabs.slab_volume();
    for (std::size_t j = 0; j < n; ++j) {
        if (volume[j] == 0.0) {  // no particle has weight here: nothing reads the coefficients
            e_[j] = 0.0;
            b_[j] = q_[j] = total_[j] = Vec3{};
            continue;
        }
        const double phi_c = std::min(phi[j], phi_cap_);
        const double e_c = 1.0 - phi_c;
        const double Phi = inv_d_volume_[j] * inv_slab;
        const Vec3 M = inv_d_momentum_[j] * inv_slab;
        const double inv_mean_d = inv_d_volume_[j] / volume[j];  // 1/<d>, the Sauter mean's
        const double e = A_ * law_->resistance(phi_c) * inv_mean_d;
        const Vec3 slip{-u_s[j].x, -u_s[j].y, U_s - u_s[j].z};
        e_[j] = e;
        b_[j] = (u_s[j] + slip * (1.0 / e_c)) * e;
        q_[j] = (slip * (phi_c * inv_mean_d / (e_c * e_c)) + (u_s[j] * Phi - M) * (1.0 / e_c)) * e;
        total_[j] = b_[j] * Phi - M * e + q_[j] * phi[j];
    }
}

void PolydisperseDrag::add_forces(const SlabFields& slabs, Particles& p, double U_s) {
    coefficients(slabs, p, U_s);
    const Vec3* v = p.v().data();
    const double* radius = p.radius().data();
    Vec3* f = p.force().data();
    for (std::size_t i = 0; i < p.size(); ++i) {
        const auto w = slabs.weights(i);
        const std::uint32_t j0 = slabs.first_slab(i);
        Vec3 fb{}, fq{};
        double fe = 0.0;
        for (std::size_t k = 0; k < w.size(); ++k) {
            fb += b_[j0 + k] * w[k];
            fe += e_[j0 + k] * w[k];
            fq += q_[j0 + k] * w[k];
        }
        f[i] += (fb - v[i] * fe) * (0.5 / radius[i]) + fq;
    }
}

void PolydisperseDrag::pressure_gradient(const SlabFields& slabs, const Particles& p, double U_s,
                                         std::span<Vec3> out) {
    EFDEM_EXPECTS(out.size() >= slabs.size());
    coefficients(slabs, p, U_s);
    std::copy_n(total_.begin(), slabs.size(), out.begin());
}

double PolydisperseDrag::pressure_drop(const SlabFields& slabs, const Particles& p, double U_s) {
    coefficients(slabs, p, U_s);
    double dp = 0.0;
    for (std::size_t j = 0; j < slabs.size(); ++j) dp += total_[j].z;
    return dp * slabs.thickness();
}

}  // namespace efdem::dem
