#pragma once
/// \file
/// Bed diagnostics: pure functions of a realization's state that a run samples every so often
/// (pressure drop, bed height, centre-of-mass heights, solid-fraction profile). They never
/// change the System. Heights in d_p, pressures in rho_s g d_p (physics.md §2).
///
/// The travelling-wave period is not here: it is a property of a *time series* and is estimated
/// by coarse::estimate_period (coarse/equation_free/estimators/period_estimator.hpp) on z_com(t),
/// by the driver or a test.

#include <vector>

#include "dem/domain.hpp"
#include "dem/particles.hpp"
#include "dem/system.hpp"

namespace efdem::dem {

/**
 * \brief Gas pressure drop across the bed, from the discrete gas momentum balance of gas_drag:
 *        Delta P = sum_j dz (-dp/dz)_j [rho_s g d_p].
 *
 * For the conservative partial-volume scheme this equals the total vertical gas force on the
 * particles divided by lx ly (physics.md §6.3). 0 when the system has no gas_drag (no gas flow).
 */
double pressure_drop(const System& system);

/// Bed weight per unit area, sum_i m_i g / (lx ly) [rho_s g d_p]: the plateau of Delta P(U_s)
/// once the bed is fluidized (43.633 for the paper's bed). `g` in units of g.
double weight_per_area(const Particles& p, const Domain& domain, double g = 1.0);
/// The same with the g of the system's gravity effect (1 without one).
double weight_per_area(const System& system);

/**
 * \brief Bed height: the height below which `fraction` of the particle volume lies (exact
 *        sphere volumes, bisection to 1e-9 d_p) [d_p].
 *
 * With the default 0.99 a few particles ejected far above the bed do not change it much (they
 * carry little volume), unlike the highest particle. For a packed bed of phi about 0.6 it lies
 * about 0.01 H below the surface. 0 for no particles. \pre 0 < fraction <= 1.
 */
double bed_height(const Particles& p, double fraction = 0.99);

/// Mass-weighted mean height of the particles of `species`, or of all particles when species
/// is negative [d_p]. 0 when there is no such particle.
double center_of_mass_height(const Particles& p, int species = -1);

/**
 * \brief Solid fraction phi_j of slabs of thickness dz from the floor to the highest particle,
 *        with the exact partial volumes of SlabFields (the floor overlap counted in slab 0).
 *
 * Allocates: a diagnostic, not for every step (the gas effect reads System::slab_fields()).
 */
std::vector<double> solid_fraction_profile(const Particles& p, const Domain& domain, double dz);

/// The same profile on exactly `slabs` slabs [0, slabs dz): a fixed layout for a time series.
/// Volume above slabs dz is left out; slabs above the highest particle read 0. \pre slabs > 0.
std::vector<double> solid_fraction_profile(const Particles& p, const Domain& domain, double dz,
                                           std::size_t slabs);

/**
 * \brief Lacey mixing index of `species` over horizontal layers of thickness `layer` from the
 *        floor (a particle belongs to the layer of its centre) [-].
 *
 *   M = (s0^2 - s^2) / (s0^2 - sr^2),  s^2 = sum_k n_k (c_k - P)^2 / N,
 *   s0^2 = P (1 - P),  sr^2 = P (1 - P) / n_mean,
 *
 * with n_k the particles in layer k, c_k the fraction of them of `species`, P that fraction in
 * the whole bed and n_mean = N / (occupied layers). M = 0 for a bed whose layers each hold one
 * species (complete segregation), about 1 for a random mixture (s^2 is then the binomial
 * variance sr^2). Layers, not a 3D grid: the model is homogeneous across the periodic
 * cross-section (the gas is 1D), so segregation is vertical only. NaN when it is undefined
 * (no particle of `species` or only such particles, or a single occupied layer). \pre layer > 0.
 */
double lacey_mixing_index(const Particles& p, SpeciesId species, double layer);

}  // namespace efdem::dem
