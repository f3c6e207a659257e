#include "dem/gas/gas_drag.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/contracts.hpp"
#include "dem/gas/slab_fields.hpp"

namespace efdem::dem {

double GasProperties::drag_number() const {
    return 18.0 * viscosity /
           (particle_density * particle_diameter * std::sqrt(particle_diameter * gravity));
}
double GasProperties::velocity_unit() const {
    return std::sqrt(gravity * particle_diameter);
}
double GasProperties::time_unit() const {
    return std::sqrt(particle_diameter / gravity);
}

GasDragSpec GasDragSpec::from_params(const Params& p) {
    GasDragSpec s;
    const std::string law = p.get_or<std::string>("law", std::string(kDragLaws[0].name));
    s.law = find_drag_law(law);
    if (!s.law)
        p.fail("law", "names an unknown drag law '" + law + "'",
               fmt::format("known drag laws: {}", fmt::join(drag_law_names(), ", ")));
    const RunParameter& u_s = GasDrag::run_parameters().front();
    s.superficial_velocity = p.get<double>(std::string(u_s.key), u_s.bounds);
    s.phi_cap = p.get_or<double>("phi_cap", 0.70, Bounds::open(0.0, 1.0));
    // Thicker than 10 d_p a slab averages over a large part of any bed (the demo bed is 15.5 d_p
    // tall, the paper's 48) and the drag no longer sees its solid-fraction profile.
    s.slab_thickness = p.get_or<double>("slab_thickness", 1.0, Bounds::closed(0.1, 10.0));
    s.polydisperse = p.get_or_choice("polydisperse", "none", {"none", "van_der_hoef"}) != "none";

    static const char* const kPhysical[] = {"gas_viscosity", "particle_density",
                                            "particle_diameter", "gravity"};
    if (p.contains("A")) {
        for (const char* key : kPhysical)
            if (p.contains(key))
                p.fail(key,
                       fmt::format("is given together with {} (A is either given or derived "
                                   "from the physical inputs)",
                                   p.full_key("A")),
                       fmt::format("either {} alone, or {}, {}, {}, {} (SI units)", p.full_key("A"),
                                   p.full_key(kPhysical[0]), p.full_key(kPhysical[1]),
                                   p.full_key(kPhysical[2]), p.full_key(kPhysical[3])));
        s.A = p.get<double>("A", Bounds::closed(1e-6, 1e6));
        s.physical = false;
    } else {
        s.gas.viscosity =
            p.get_or<double>("gas_viscosity", 1.8e-5, Bounds::closed(1e-7, 1e3));  // Pa s
        s.gas.particle_density =
            p.get_or<double>("particle_density", 900.0, Bounds::closed(1.0, 1e5));  // kg/m^3
        s.gas.particle_diameter =
            p.get_or<double>("particle_diameter", 1e-4, Bounds::closed(1e-8, 1.0));    // m
        s.gas.gravity = p.get_or<double>("gravity", 9.81, Bounds::closed(1e-3, 1e4));  // m/s^2
        s.A = s.gas.drag_number();
        s.physical = true;
    }
    return s;
}

namespace {
/// The largest diameter ratio the polydisperse closure was fitted for (van der Hoef et al. 2005,
/// Beetstra et al. 2007: 1:1.5 to 1:4).
constexpr double kMaxDiameterRatio = 4.0;

void check_diameters(const EffectSetup& s, const GasDragSpec& spec) {
    double d_min = s.species[0].diameter, d_max = d_min;
    for (std::size_t k = 0; k < s.species.size(); ++k) {
        d_min = std::min(d_min, s.species[static_cast<SpeciesId>(k)].diameter);
        d_max = std::max(d_max, s.species[static_cast<SpeciesId>(k)].diameter);
    }
    if (!spec.polydisperse && (d_min != 1.0 || d_max != 1.0))
        s.root.scope("species").fail(
            "diameter",
            "is not 1 for every species, but gas_drag's drag law (Eq. 2) is written for one "
            "particle size, the unit length d_p",
            "1 for every species, or gas_drag.polydisperse = van_der_hoef for spheres of several "
            "sizes");
    if (spec.polydisperse && d_max > kMaxDiameterRatio * d_min * (1.0 + 1e-12))
        s.root.scope("species").fail(
            "diameter",
            fmt::format("spans a diameter ratio of {:.4g}, beyond the range of "
                        "gas_drag.polydisperse = van_der_hoef (fitted to lattice-Boltzmann "
                        "simulations of ratios up to 1:4)",
                        d_max / d_min),
            fmt::format("diameters within a ratio of {:g} of each other", kMaxDiameterRatio));
}

GasDragSpec checked_spec(const EffectSetup& s) {
    GasDragSpec spec = GasDragSpec::from_params(s.scope);
    check_diameters(s, spec);
    // Above the terminal velocity of an isolated sphere of the heaviest species (rho d^2 / A,
    // physics.md §3.3) the gas carries every particle to the lid: no bed is left to fluidize.
    double terminal = 0;
    for (std::size_t k = 0; k < s.species.size(); ++k) {
        const Species& sp = s.species[static_cast<SpeciesId>(k)];
        terminal = std::max(terminal, sp.density * sp.diameter * sp.diameter / spec.A);
    }
    if (spec.superficial_velocity > terminal)
        s.scope.fail("superficial_velocity",
                     fmt::format("exceeds the terminal velocity rho d^2/A = {:.4g} of an isolated "
                                 "sphere of the heaviest species (A = {:.6g}): the gas would carry "
                                 "every particle to the lid",
                                 terminal, spec.A),
                     fmt::format("[0, {:.4g}]", terminal));
    // The 1D gas averages phi over horizontal slabs: at least two must fit below the lid.
    if (s.domain.has_lid() && spec.slab_thickness > 0.5 * s.domain.lid_height)
        s.scope.fail("slab_thickness",
                     fmt::format("leaves fewer than two slabs below the lid at domain.lid = {:g}: "
                                 "the 1D gas would see no solid-fraction profile",
                                 s.domain.lid_height),
                     fmt::format("[0.1, {:g}] (half of domain.lid; 1, one diameter, is usual)",
                                 0.5 * s.domain.lid_height));
    return spec;
}

/// The per-slab terms of Eq. (1), written once: the drag per unit volume c = A r(phi_c) and
/// the pressure-gradient velocity g = (u_s - U_s)/(1 - phi_c)^2.
struct SlabTerms {
    double c;
    Vec3 g;
};
inline SlabTerms slab_terms(const GasDragSpec& s, double phi, const Vec3& u_s) {
    const double phi_c = std::min(phi, s.phi_cap);
    const double q = 1.0 / (1.0 - phi_c);
    const Vec3 slip{u_s.x, u_s.y, u_s.z - s.superficial_velocity};
    return {s.A * s.law->resistance(phi_c), slip * (q * q)};
}
}  // namespace

GasDrag::GasDrag(const EffectSetup& s) : GasDrag(checked_spec(s), s.species) {}

std::span<const RunParameter> GasDrag::run_parameters() {
    static const RunParameter kParameters[] = {
        {"superficial_velocity", Bounds::closed(0.0, kMaxSuperficialVelocity),
         "U_s, the superficial gas velocity [sqrt(g d_p)]"},
    };
    return kParameters;
}

void GasDrag::set_parameter(std::string_view key, double value) {
    EFDEM_EXPECTS(key == run_parameters().front().key);
    (void)key;  // the only one
    set_superficial_velocity(value);
}

GasDrag::GasDrag(const GasDragSpec& spec, const SpeciesTable& species) : spec_(spec) {
    for (std::size_t k = 0; k < species.size(); ++k) {
        density_.push_back(species[static_cast<SpeciesId>(k)].density);
        diameter_.push_back(species[static_cast<SpeciesId>(k)].diameter);
        species_names_.push_back(species[static_cast<SpeciesId>(k)].name);
    }
    if (spec_.polydisperse) polydisperse_.emplace(spec_.A, spec_.law, spec_.phi_cap);
}

double GasDrag::relaxation_time() const {
    // Drag per unit volume of a sphere of diameter d among spheres of Sauter mean <d>: A r /
    // (d <d>) (one size: A r); the shortest time is that of the smallest sphere among the
    // smallest (d = <d> = d_min) of the lightest species.
    const double d_min = *std::min_element(diameter_.begin(), diameter_.end());
    double shortest = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < density_.size(); ++k)
        shortest = std::min(shortest, density_[k] * diameter_[k] * d_min);
    return shortest * std::pow(1.0 - spec_.phi_cap, 2.65) / spec_.A;
}

std::string GasDrag::relaxation_label() const {
    return fmt::format(
        "drag relaxation time tau = rho (1 - phi_cap)^2.65 / A = {:.4g} of the lightest species "
        "(gas_drag.A = {:g}, gas_drag.phi_cap = {:g})",
        relaxation_time(), spec_.A, spec_.phi_cap);
}

std::string GasDrag::relaxation_remedy(double dt) const {
    return fmt::format("gas_drag.A <= {:.4g}", spec_.A * relaxation_time() / dt);
}

Needs GasDrag::needs() const {
    return {.slab_fields = true, .slab_thickness = spec_.slab_thickness};
}

void GasDrag::slab_coefficients(const SlabFields& slabs) {
    const std::size_t n = slabs.size();
    if (c_.size() < n) {
        c_.resize(n);
        a_.resize(n);
    }
    const auto phi = slabs.phi();
    const auto u_s = slabs.solid_velocity();
    const auto volume = slabs.solid_volume();
    for (std::size_t j = 0; j < n; ++j) {
        if (volume[j] == 0.0) {  // no particle has weight here: nothing reads c_j, a_j
            c_[j] = 0.0;
            a_[j] = Vec3{};
            continue;
        }
        const SlabTerms t = slab_terms(spec_, phi[j], u_s[j]);
        c_[j] = t.c;
        a_[j] = (u_s[j] - t.g) * t.c;
    }
}

void GasDrag::add_forces(ForceContext& ctx) {
    EFDEM_EXPECTS(ctx.slabs != nullptr);
    const SlabFields& slabs = *ctx.slabs;
    if (polydisperse_) {
        polydisperse_->add_forces(slabs, ctx.particles, spec_.superficial_velocity);
        return;
    }
    slab_coefficients(slabs);
    Particles& p = ctx.particles;
    const std::size_t n = p.size();
    const Vec3* v = p.v().data();
    Vec3* f = p.force().data();
    const std::uint32_t* first = slabs.first_data();
    const std::uint8_t* count = slabs.count_data();
    const double* w = slabs.weight_data();
    const std::size_t stride = static_cast<std::size_t>(slabs.max_slabs_per_particle());
    const double* c = c_.data();
    const Vec3* a = a_.data();
    for (std::size_t i = 0; i < n; ++i, w += stride) {
        const std::uint32_t j0 = first[i];
        Vec3 fa = a[j0] * w[0];
        double fc = c[j0] * w[0];
        for (int k = 1; k < count[i]; ++k) {  // most spheres cut one plane: one more slab
            fa += a[j0 + static_cast<std::uint32_t>(k)] * w[k];
            fc += c[j0 + static_cast<std::uint32_t>(k)] * w[k];
        }
        f[i] += fa - v[i] * fc;
    }
}

void GasDrag::pressure_gradient(const SlabFields& slabs, const Particles& p,
                                std::span<Vec3> out) const {
    EFDEM_EXPECTS(out.size() >= slabs.size());
    if (polydisperse_) {
        polydisperse_->pressure_gradient(slabs, p, spec_.superficial_velocity, out);
        return;
    }
    const auto phi = slabs.phi();
    const auto u_s = slabs.solid_velocity();
    for (std::size_t j = 0; j < slabs.size(); ++j) {
        const SlabTerms t = slab_terms(spec_, phi[j], u_s[j]);
        out[j] = t.g * (-phi[j] * t.c);
    }
}

double GasDrag::pressure_drop(const SlabFields& slabs, const Particles& p) const {
    if (polydisperse_) return polydisperse_->pressure_drop(slabs, p, spec_.superficial_velocity);
    const auto phi = slabs.phi();
    const auto u_s = slabs.solid_velocity();
    double dp = 0.0;
    for (std::size_t j = 0; j < slabs.size(); ++j) {
        const SlabTerms t = slab_terms(spec_, phi[j], u_s[j]);
        dp -= phi[j] * t.c * t.g.z;
    }
    return dp * slabs.thickness();
}

double GasDrag::minimum_fluidization_velocity(double density, double phi, double diameter) const {
    const double phi_c = std::min(phi, spec_.phi_cap);
    return density * diameter * diameter * (1.0 - phi_c) * (1.0 - phi_c) /
           (spec_.A * spec_.law->resistance(phi_c));
}

void GasDrag::describe(EffectReport& r) const {
    r.add("law", fmt::format("{}: {}", spec_.law->name, spec_.law->formula));
    if (spec_.physical)
        r.add("A", fmt::format("{:.6g} = 18 mu_g/(rho_s d_p^1.5 g^0.5) from mu_g = {:g} Pa s, "
                               "rho_s = {:g} kg/m^3, d_p = {:g} m, g = {:g} m/s^2 (1/A = {:.5g})",
                               spec_.A, spec_.gas.viscosity, spec_.gas.particle_density,
                               spec_.gas.particle_diameter, spec_.gas.gravity, 1.0 / spec_.A));
    else
        r.add("A", fmt::format("{:.6g} (given; 1/A = {:.5g})", spec_.A, 1.0 / spec_.A));
    if (spec_.physical)
        r.add("superficial velocity U_s",
              fmt::format("{:g} sqrt(g d_p) = {:.4g} cm/s (time unit sqrt(d_p/g) = {:.4g} ms)",
                          spec_.superficial_velocity,
                          100 * spec_.superficial_velocity * spec_.gas.velocity_unit(),
                          1000 * spec_.gas.time_unit()));
    else
        r.add("superficial velocity U_s",
              fmt::format("{:g} sqrt(g d_p)", spec_.superficial_velocity));
    r.add("slabs", fmt::format("thickness {:g} d_p from the floor to the highest particle; phi "
                               "capped at {:g} inside the (1-phi) factors",
                               spec_.slab_thickness, spec_.phi_cap));
    if (spec_.polydisperse)
        r.add("polydisperse",
              "van_der_hoef: drag on a sphere of diameter d among spheres of Sauter mean <d> "
              "A r(phi)/(d <d>) per unit volume (van der Hoef et al. 2005 without the cubic term: "
              "the law above for one size)");
    for (std::size_t k = 0; k < density_.size(); ++k) {
        const double d = diameter_[k];
        const double vt = density_[k] * d * d / spec_.A;  // Stokes: m g = V A v_t / d^2
        r.add(fmt::format("species {}", species_names_[k]),
              fmt::format("Stokes terminal velocity and relaxation time {:.4g}; settles at U_s - "
                          "{:.4g} = {:.4g} when isolated; U_mf at phi = 0.6: {:.4g}",
                          vt, vt, spec_.superficial_velocity - vt,
                          minimum_fluidization_velocity(density_[k], 0.6, d)));
    }
    // Which species U_s fluidizes on its own: between their U_mf a bed demixes into a fluidized
    // and a packed part, and can lose its fluidization as the species that is not fluidized
    // gathers at the bottom (at U_s = 0.19 every realization of the demo bed comes to rest).
    const std::vector<std::string> packed = species_not_fluidized();
    std::vector<std::string> fluidized;
    for (const std::string& name : species_names_)
        if (std::find(packed.begin(), packed.end(), name) == packed.end())
            fluidized.push_back(name);
    if (!fluidized.empty() && !packed.empty())
        r.add("fluidization",
              fmt::format("U_s = {:g} fluidizes {} but not {} on its own (U_mf at phi = 0.6): "
                          "where the {} spheres gather, the bed can defluidize and come to rest",
                          spec_.superficial_velocity, fmt::join(fluidized, ", "),
                          fmt::join(packed, ", "), fmt::join(packed, ", ")));
    else
        r.add("fluidization",
              fmt::format("U_s = {:g} is {} every species' U_mf at phi = 0.6",
                          spec_.superficial_velocity, packed.empty() ? "above" : "below"));
}

std::vector<std::string> GasDrag::species_not_fluidized() const {
    std::vector<std::string> out;
    for (std::size_t k = 0; k < density_.size(); ++k)
        if (spec_.superficial_velocity <=
            minimum_fluidization_velocity(density_[k], 0.6, diameter_[k]))
            out.push_back(species_names_[k]);
    return out;
}

}  // namespace efdem::dem
