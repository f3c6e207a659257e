#pragma once
/// \file
/// GasDrag: the 1D, locally averaged gas of the paper (Eq. 1-2; physics.md §3-4): drag plus the
/// gas pressure-gradient force, computed algebraically from the slab fields phi_j, u_s,j. Doc:
/// docs/effects/gas_drag.md.
///
/// Force on particle i, summed over the slabs j it intersects (partial volume V_ij):
///
///   F_i = sum_j V_ij A r(phi_j) [ (u_s,j - v_i) - (u_s,j - U_s)/(1 - phi_c,j)^2 ]
///
/// with U_s = (0, 0, U_s) the superficial gas velocity, r the drag law's resistance
/// (dem/gas/drag_laws.hpp; r = (1-phi)^-2.65 for wen_yu_low_re), phi_c,j = min(phi_j, phi_cap)
/// used in every (1-phi) factor (r included), and
/// A = 18 mu_g/(rho_s d_p^1.5 g^0.5), the Stokes drag per unit particle volume per unit slip.
///
/// Units: force [rho_s g d_p^3], V [d_p^3], velocities [sqrt(g d_p)], A dimensionless.
/// Limits:
/// * phi_j -> 0 (an isolated particle, u_s,j = v_i): F_i = V_i A (U_s - v_i)(1 + O(phi)), Stokes
///   drag toward the gas velocity. Nothing divides by phi, so an empty slab is no special case.
/// * The cap (default 0.70) bounds (1-phi)^-4.65 at 270 where transient overlaps push a slab's
///   phi toward 1; a packed bed (phi about 0.6) is below it, so the cap is inactive there.
/// * Conservation: sum_i F_i = lx ly sum_j dz (-grad p)_j exactly, with the discrete gas
///   pressure gradient (-grad p)_j = phi_j A r(phi_c,j) (U_s - u_s,j)/(1 - phi_c,j)^2
///   (pressure_gradient()); its z part summed over the slabs is the pressure drop.
/// Not done: gas inertia and weight (neglected, physics.md §3.2), buoyancy (absent from Eq. 1),
/// fluid torque, horizontal gas flow (the vector form applies Eq. 1 componentwise, §3.3).
/// Spheres of several diameters: `gas_drag.polydisperse = van_der_hoef` (PolydisperseDrag,
/// dem/gas/polydisperse_drag.hpp), whose limit for one size is this kernel; without it every
/// species must have diameter 1 (Eq. 2 is written for one particle size d_p).

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/registry.hpp"
#include "dem/effect.hpp"
#include "dem/gas/drag_laws.hpp"
#include "dem/gas/polydisperse_drag.hpp"

namespace efdem::dem {

/// Physical inputs from which A is derived (SI units).
struct GasProperties {
    double viscosity = 1.8e-5;        ///< mu_g [Pa s] (air)
    double particle_density = 900;    ///< rho_s of the density-1 species [kg/m^3]
    double particle_diameter = 1e-4;  ///< d_p [m]
    double gravity = 9.81;            ///< g [m/s^2]

    /// A = 18 mu_g/(rho_s d_p^1.5 g^0.5) [-]; 0.114939 for the defaults.
    double drag_number() const;
    /// The velocity unit sqrt(g d_p) [m/s] and the time unit sqrt(d_p/g) [s].
    double velocity_unit() const;
    double time_unit() const;
};

/// The scene's choice for gas_drag (keys: docs/effects/gas_drag.md).
struct GasDragSpec {
    const DragLaw* law = &kDragLaws[0];
    double A = 0.114939;                ///< dimensionless Stokes drag number
    double superficial_velocity = 0.0;  ///< U_s [sqrt(g d_p)], upward
    double phi_cap = 0.70;              ///< cap on phi inside the (1-phi) factors
    double slab_thickness = 1.0;        ///< dz of the slab fields [d_p]
    /// gas_drag.polydisperse = van_der_hoef: the closure for spheres of several diameters
    /// (PolydisperseDrag); none: one size, diameter 1.
    bool polydisperse = false;
    /// Set when A was derived from physical inputs (for reports in physical units).
    bool physical = false;
    GasProperties gas;

    /// Reads the `gas_drag.` scope: A either as `A` or from the physical keys, not both.
    static GasDragSpec from_params(const Params& scope);
};

/// The largest gas_drag.superficial_velocity a scene (or a continuation) may set [sqrt(g d_p)].
inline constexpr double kMaxSuperficialVelocity = 1e3;

class GasDrag final : public Effect {
  public:
    explicit GasDrag(const EffectSetup& setup);
    GasDrag(const GasDragSpec& spec, const SpeciesTable& species);

    std::string_view name() const override { return "gas_drag"; }
    Needs needs() const override;
    void add_forces(ForceContext& ctx) override;
    void describe(EffectReport& r) const override;
    /// tau = rho_min (1 - phi_cap)^2.65 / A: the drag relaxation time of the lightest species
    /// at the densest packing the law sees (physics.md §3.3), the shortest the drag imposes.
    double relaxation_time() const override;
    std::string relaxation_label() const override;
    /// "gas_drag.A <= x": the A at which tau equals dt.
    std::string relaxation_remedy(double dt) const override;

    const GasDragSpec& spec() const { return spec_; }
    /// The keys a run may change between steps (the registry row lists them): U_s, read by the
    /// scene with these same bounds.
    static std::span<const RunParameter> run_parameters();
    /// Changes U_s between steps (a U_s sweep, continuation in U_s).
    void set_superficial_velocity(double u) { spec_.superficial_velocity = u; }
    /// key = "superficial_velocity": set_superficial_velocity(value).
    void set_parameter(std::string_view key, double value) override;

    /// (-grad p)_j of the discrete gas momentum balance, one vector per slab [rho_s g]; its z
    /// component is -dp/dz. `p`: the particles the slabs were updated from (the polydisperse
    /// closure reads their diameters). \pre out.size() >= slabs.size().
    void pressure_gradient(const SlabFields& slabs, const Particles& p, std::span<Vec3> out) const;
    /// Pressure drop across the bed, sum_j dz (-dp/dz)_j [rho_s g d_p]. Equals the total
    /// vertical gas force on the particles divided by lx ly.
    double pressure_drop(const SlabFields& slabs, const Particles& p) const;

    /// Minimum fluidization velocity of a uniform packed layer of one species, of density
    /// `density` [rho_s] and `diameter` [d_p], at solid fraction phi (physics.md §6.1):
    /// U_mf = density diameter^2 (1-phi)^2/(A r(phi)).
    double minimum_fluidization_velocity(double density, double phi, double diameter = 1.0) const;
    /// The species that U_s does not fluidize on their own (U_mf at phi = 0.6 at or above U_s),
    /// by name. With some species fluidized and some not, a bed can defluidize and come to rest
    /// where the others gather as it demixes.
    std::vector<std::string> species_not_fluidized() const;

  private:
    /// Per-slab coefficients of the force kernel: c_j = A r(phi_c,j) and
    /// a_j = c_j (u_s,j - (u_s,j - U_s)/(1 - phi_c,j)^2), so that F_i = sum_j V_ij (a_j - c_j v_i).
    void slab_coefficients(const SlabFields& slabs);

    GasDragSpec spec_;
    std::vector<double> density_;   ///< per species [rho_s], for reports
    std::vector<double> diameter_;  ///< per species [d_p]
    std::vector<std::string> species_names_;
    std::vector<double> c_;  ///< per slab (grows, never shrinks)
    std::vector<Vec3> a_;
    /// The closure for several diameters (spec_.polydisperse); its scratch arrays change in
    /// the const queries (pressure_gradient, pressure_drop).
    mutable std::optional<PolydisperseDrag> polydisperse_;
};

}  // namespace efdem::dem
