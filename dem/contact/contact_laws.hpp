#pragma once
/// \file
/// Contact-law kernels: the Cundall-Strack soft-sphere contact (physics.md §5.1), written once
/// and inlined into both the particle-particle and the particle-wall loops.
///
/// Symbols (one contact between particle i and partner j; j may be a wall):
///   n      unit normal from j to i;  delta = r_i + r_j - |x_i - x_j| > 0  overlap [d_p]
///   v_rel  = v_i - v_j;  v_n = (v_rel . n)  normal relative velocity (< 0 when approaching)
///   v_t    = v_rel - v_n n - (r_i w_i + r_j w_j) x n  tangential velocity of the contact point
///   F_n    = s_e(delta) k_n delta - s_d(delta) eta_n v_n            normal force on i, along n
///   xi    <- xi - (xi . n) n ;  xi <- xi + v_t dt                    history spring (if any)
///   F_t    = -s_e k_t xi - s_d eta_t v_t, limited to mu |F_n|;  on sliding
///            xi = -(F_t + s_d eta_t v_t)/(s_e k_t)                   (Silbert et al. 2001)
///   torque on i: -r_i n x F_t;  on j: -r_j n x F_t
/// with the stiffness scale s_e and damping scale s_d of the normal model: 1 and 1 for Hooke;
/// sqrt(R_eff delta) and (R_eff delta)^(1/4) for Hertz (Tsuji et al. 1992 damping, which gives
/// a restitution coefficient independent of the impact velocity).
///
/// Units: force [rho_s g d_p^3], k [force/length], eta [mass/time], mu dimensionless.
/// Not done here: the overlap test and the neighbour search (the loops do them).

#include <cmath>

#include "core/vec3.hpp"

namespace efdem::dem {

/// Resolved coefficients of one pair type (species pair, or species and wall).
struct ContactCoeffs {
    double kn = 0;     ///< normal stiffness [force/length] (Hertz: [force/length^1.5])
    double kt = 0;     ///< tangential stiffness
    double eta_n = 0;  ///< normal damping [mass/time]
    double eta_t = 0;  ///< tangential damping
    double mu = 0;     ///< Coulomb friction coefficient
    double r_eff = 0;  ///< effective radius r_i r_j/(r_i + r_j) (r_i for a wall) [d_p]
};

/// Linear spring (Cundall & Strack 1979).
struct HookeNormal {
    static constexpr const char* kName = "hooke";
    static double elastic_scale(double, double) { return 1.0; }
    static double damping_scale(double, double) { return 1.0; }
    /// Elastic energy stored at overlap delta.
    static double energy(double kn, double delta, double) { return 0.5 * kn * delta * delta; }
};

/// Hertzian spring F = k_n sqrt(R_eff delta) delta with Tsuji damping (R_eff delta)^(1/4).
struct HertzNormal {
    static constexpr const char* kName = "hertz";
    static double elastic_scale(double delta, double r_eff) { return std::sqrt(r_eff * delta); }
    static double damping_scale(double delta, double r_eff) {
        return std::sqrt(std::sqrt(r_eff * delta));
    }
    static double energy(double kn, double delta, double r_eff) {
        return 0.4 * kn * std::sqrt(r_eff * delta) * delta * delta;
    }
};

/// Frictionless: no tangential force, no history.
struct NoTangential {
    static constexpr bool kHistory = false;
    static constexpr const char* kName = "none";
};
/// Tangential spring-dashpot with history and Coulomb limit.
struct HistoryTangential {
    static constexpr bool kHistory = true;
    static constexpr const char* kName = "history";
};

/// Force on i (normal + tangential) and the tangential part alone (for torques).
struct ContactForce {
    Vec3 total;
    Vec3 tangential;
};

/**
 * \brief Adds the elastic energy stored in one contact to `e`: the normal spring
 *        Normal::energy, then, when the contact has a history spring `xi`, the tangential
 *        spring 0.5 s_e k_t |xi|^2 (two additions, in that order).
 */
template <class Normal>
inline void add_contact_energy(double& e, double delta, const ContactCoeffs& c, const Vec3* xi) {
    e += Normal::energy(c.kn, delta, c.r_eff);
    if (xi) e += 0.5 * Normal::elastic_scale(delta, c.r_eff) * c.kt * norm2(*xi);
}

/**
 * \brief One contact: forces on i from the kernel equations in the file header.
 * \param n       unit normal from j to i
 * \param delta   overlap (> 0)
 * \param v_rel   v_i - v_j
 * \param w_sum   r_i w_i + r_j w_j  (r_i w_i for a wall)
 * \param xi      history spring of the pair (updated in place); ignored without history
 */
template <class Normal, class Tangential>
inline ContactForce contact_force(const Vec3& n, double delta, const Vec3& v_rel, const Vec3& w_sum,
                                  const ContactCoeffs& c, double dt, Vec3* xi) {
    const double s_e = Normal::elastic_scale(delta, c.r_eff);
    const double s_d = Normal::damping_scale(delta, c.r_eff);
    const double vn = dot(v_rel, n);
    const double fn = s_e * c.kn * delta - s_d * c.eta_n * vn;
    ContactForce out{n * fn, Vec3{}};
    if constexpr (Tangential::kHistory) {
        const Vec3 vt = v_rel - n * vn - cross(w_sum, n);
        Vec3 s = *xi;
        s -= n * dot(s, n);  // rotate the spring into the current tangent plane
        s += vt * dt;
        const double kt = s_e * c.kt;
        const double eta_t = s_d * c.eta_t;
        Vec3 ft = -(s * kt + vt * eta_t);  // = -(s kt) - vt eta_t exactly, one negation
        const double ft2 = norm2(ft);
        const double limit = c.mu * std::abs(fn);
        if (ft2 > limit * limit) {
            // Sliding: scale the force to the Coulomb limit, and the spring to match it.
            ft *= limit / std::sqrt(ft2);
            s = (ft + vt * eta_t) * (-1.0 / kt);
        }
        *xi = s;
        out.total += ft;
        out.tangential = ft;
    }
    return out;
}

}  // namespace efdem::dem
