#pragma once
/// \file
/// Drag laws for the 1D gas of gas_drag (physics.md §3): the interphase momentum-transfer
/// coefficient beta(phi), chosen by keyword from the table kDragLaws.
///
/// Each law is given as its *resistance* r(phi), the drag per unit particle volume relative to
/// Stokes drag on an isolated sphere:
///
///   beta(phi)/phi = (18 mu_g / d_p^2) r(phi),     r(0) = 1 for every law,
///
/// so that in the dimensionless units of physics.md §2 the drag per unit particle volume is
/// A r(phi) [rho_s g / sqrt(g d_p)] with A = 18 mu_g/(rho_s d_p^1.5 g^0.5). Writing the law as
/// beta/phi (never beta and a division by phi) keeps phi -> 0 finite: an empty or dilute slab
/// gives Stokes drag.
///
/// To add a law: write its resistance function here (with its equation, reference and range of
/// validity) and add ONE row to kDragLaws. A law that depends on the slip Reynolds number would
/// need the slab's slip velocity as a second argument; none does yet.
/// Not done here: the phi cap and the pressure-gradient term (gas_drag applies both).

#include <cmath>
#include <string>
#include <string_view>
#include <vector>

namespace efdem::dem {

/**
 * \brief Wen & Yu (1966) in the low-Reynolds-number limit (Eq. 2 of the paper):
 *        beta = 18 (mu_g/d_p^2) phi (1 - phi)^-2.65, i.e. r(phi) = (1 - phi)^-2.65.
 *
 * Valid for Re_p = rho_g |u_g - u_s| d_p/mu_g below about 0.1 (the paper's regime, physics.md
 * §6.4); with the pressure gradient it gives the Richardson-Zaki exponent n = 4.65.
 * \pre 0 <= phi < 1 (gas_drag caps phi below 1 first).
 */
inline double wen_yu_low_re_resistance(double phi) {
    return std::pow(1.0 - phi, -2.65);
}

/// One row of the drag-law table.
struct DragLaw {
    std::string_view name;             ///< the keyword of `gas_drag.law`
    double (*resistance)(double phi);  ///< r(phi) = (beta/phi) / (18 mu_g/d_p^2), r(0) = 1
    std::string_view formula;          ///< for the run log and `efdem --check`
};

/// THE table of drag laws.
inline constexpr DragLaw kDragLaws[] = {
    {"wen_yu_low_re", &wen_yu_low_re_resistance,
     "beta/phi = 18 mu_g/d_p^2 (1-phi)^-2.65 (Wen & Yu 1966, Re_p -> 0)"},
};

/// The law called `name`, or nullptr.
inline const DragLaw* find_drag_law(std::string_view name) {
    for (const auto& law : kDragLaws)
        if (law.name == name) return &law;
    return nullptr;
}

/// The keywords of all laws, in table order.
inline std::vector<std::string> drag_law_names() {
    std::vector<std::string> out;
    for (const auto& law : kDragLaws) out.emplace_back(law.name);
    return out;
}

}  // namespace efdem::dem
