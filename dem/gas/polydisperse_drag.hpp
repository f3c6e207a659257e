#pragma once
/// \file
/// PolydisperseDrag: gas_drag for spheres of several diameters (`gas_drag.polydisperse =
/// van_der_hoef`; docs/effects/gas_drag.md, "Spheres of several sizes").
///
/// The closure. van der Hoef, Beetstra & Kuipers, J. Fluid Mech. 528 (2005) 233-254, found from
/// lattice-Boltzmann simulations of random bidisperse arrays in Stokes flow that the total fluid
/// force on a sphere of diameter d_i is that of the monodisperse law at the local solid fraction
/// phi, scaled by the sphere's size relative to the Sauter mean diameter <d>:
///
///   F_i = 3 pi mu_g d_i U F(phi) [ (1 - phi) y_i + phi y_i^2 + 0.064 (1 - phi) y_i^3 ],
///   y_i = d_i / <d>,   1/<d> = sum_k (phi_k/phi) / d_k,   U the superficial slip.
///
/// The cubic term (a 2.6-4.5 % excess at y = 1, which would make a bed of one size feel 1.026-
/// 1.045 times the monodisperse law) is dropped here, as MFIX does for its drag-only ("model A")
/// form of the same correction (Beetstra et al., AIChE J. 53 (2007) 489 and its erratum, 3020):
/// the paper's law (Eq. 2, F = (1 - phi)^-4.65) is then the exact limit of one size. Split into
/// drag and pressure-gradient force as in Eq. 1, this is the drag coefficient per particle
///
///   D_i = 3 pi mu_g (d_i^2 / <d>) (1 - phi)^-2.65,  beta_i = 18 mu_g phi_i (1-phi)^-2.65/(d_i
///   <d>),
///
/// with the gas's continuity and momentum balance over every species:
///
///   (1 - phi) u_g = U_s - phi u_s,     -(1 - phi) dp/dz = sum_k beta_k (u_g - u_k),
///   force on particle i = D_i (u_g - v_i) + V_i (-dp/dz).
///
/// In the dimensionless units of physics.md §2 (lengths in d_p, the unit of A) the force per
/// unit particle volume in slab j is, with c = A r(phi_c), Phi = sum_i V_ij / d_i / V_slab
/// (so that 1/<d> = Phi/phi), M = sum_i V_ij v_i / d_i / V_slab and slip = U_s - u_s:
///
///   F_ij / V_ij = (c/<d>) [ (u_s - v_i)/d_i + slip (1/d_i + phi_c/(<d> e_c)) / e_c
///                           + (Phi u_s - M) / e_c ],     e_c = 1 - phi_c,
///
/// phi_c = min(phi, phi_cap) in every (1 - phi) factor, as in the one-size kernel. With one
/// diameter 1 this is that kernel's force term by term (Phi u_s - M = 0, <d> = 1); the pressure
/// gradient reported is the slabs' total gas force per unit volume, so the pressure drop is the
/// vertical gas force on the particles over the area exactly.
///
/// Valid for diameter ratios up to 4 (the range of both papers' simulations) and Re_p -> 0; the
/// correction was fitted alongside the BVK monodisperse law, not Richardson-Zaki's, so using it
/// on Eq. 2 is an assumption stated in the doc.
///
/// \code
/// PolydisperseDrag drag(A, law, phi_cap);
/// drag.add_forces(slabs, particles, U_s);     // every step, after slabs.update()
/// double dp = drag.pressure_drop(slabs, particles, U_s);
/// \endcode

#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "dem/gas/drag_laws.hpp"
#include "dem/particles.hpp"

namespace efdem::dem {

class SlabFields;

class PolydisperseDrag {
  public:
    /// A: Stokes drag number of a sphere of diameter 1; law: r(phi); phi_cap in (0, 1).
    PolydisperseDrag(double A, const DragLaw* law, double phi_cap);

    /// Adds every particle's gas force at superficial velocity U_s. \pre slabs updated from p.
    void add_forces(const SlabFields& slabs, Particles& p, double U_s);
    /// The total gas force per unit volume of each slab, (-grad p)_j [rho_s g].
    /// \pre out.size() >= slabs.size().
    void pressure_gradient(const SlabFields& slabs, const Particles& p, double U_s,
                           std::span<Vec3> out);
    /// sum_j dz (-dp/dz)_j [rho_s g d_p]: the vertical gas force on the particles over lx ly.
    double pressure_drop(const SlabFields& slabs, const Particles& p, double U_s);

  private:
    /// Per slab: e = c/<d>, b = e (u_s + slip/e_c), q = e (slip phi_c/(<d> e_c^2) + (Phi u_s -
    /// M)/e_c), so that F_i = sum_j V_ij [(b_j - e_j v_i)/d_i + q_j]; and the total force per
    /// unit volume t = Phi b - e M + phi q.
    void coefficients(const SlabFields& slabs, const Particles& p, double U_s);

    double A_;
    const DragLaw* law_;
    double phi_cap_;
    std::vector<double> inv_d_volume_;  ///< sum_i V_ij / d_i, per slab
    std::vector<Vec3> inv_d_momentum_;  ///< sum_i V_ij v_i / d_i, per slab
    std::vector<double> e_;
    std::vector<Vec3> b_, q_, total_;
};

}  // namespace efdem::dem
