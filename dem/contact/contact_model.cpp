#include "dem/contact/contact_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/contracts.hpp"
#include "core/param_table.hpp"

namespace efdem::dem {

namespace {

/// Reads a real from `scope`, or from `fallback` when scope lacks it.
double real_or_fallback(const Params& scope, const Params* fallback, const char* key,
                        const Bounds& b) {
    if (!scope.contains(key) && fallback && fallback->contains(key))
        return fallback->get<double>(key, b);
    return scope.get<double>(key, b);
}
double real_or_fallback(const Params& scope, const Params* fallback, const char* key, double def,
                        const Bounds& b) {
    if (!scope.contains(key) && fallback && fallback->contains(key))
        return fallback->get<double>(key, b);
    return scope.get_or<double>(key, def, b);
}
std::string choice_or_fallback(const Params& scope, const Params* fallback, const char* key,
                               const std::string& def, const std::vector<std::string>& allowed) {
    if (!scope.contains(key) && fallback && fallback->contains(key))
        return fallback->get_choice(key, allowed);
    return scope.get_or_choice(key, def, allowed);
}

}  // namespace

ContactSpec ContactSpec::from_params(const Params& p, const Params* fb) {
    ContactSpec s;
    const std::string normal = choice_or_fallback(p, fb, "normal", "hooke", {"hooke", "hertz"});
    s.normal = normal == "hertz" ? NormalModel::hertz : NormalModel::hooke;
    // Physically sensible ranges in the units of physics.md (m g / d_p for stiffnesses): what
    // lies outside is a unit mistake or a typo, not a material.
    s.kn = real_or_fallback(p, fb, "kn", Bounds::closed(1.0, 1e12));
    const std::string damping =
        choice_or_fallback(p, fb, "damping", "restitution", {"restitution", "gamma", "none"});
    if (damping == "restitution") {
        s.damping = DampingModel::restitution;
        s.restitution = real_or_fallback(
            p, fb, "restitution",
            s.normal == NormalModel::hertz ? kHertzRestitutionRange : Bounds::closed(1e-3, 1.0));
    } else if (damping == "gamma") {
        if (s.normal == NormalModel::hertz)
            p.fail("damping", "'gamma' (LAMMPS' single gamma_n) is only defined here for hooke",
                   "restitution or none with normal = hertz");
        s.damping = DampingModel::gamma;
        s.gamma_n = real_or_fallback(p, fb, "gamma_n", Bounds::closed(0.0, 1e12));
    } else {
        s.damping = DampingModel::none;
    }
    const std::string tangential =
        choice_or_fallback(p, fb, "tangential", "history", {"history", "none"});
    s.tangential = tangential == "none" ? TangentialModel::none : TangentialModel::history;
    if (s.tangential == TangentialModel::history) {
        s.kt = real_or_fallback(p, fb, "kt", 2.0 / 7.0 * s.kn, Bounds::closed(1e-6 * s.kn, s.kn));
        s.tangential_damping =
            real_or_fallback(p, fb, "tangential_damping", 0.5, Bounds::closed(0.0, 1.0));
        // Coulomb friction: measured granular values are 0.05-1; above 10 is a unit mistake.
        s.mu = real_or_fallback(p, fb, "mu", Bounds::closed(0.0, 10.0));
    }
    return s;
}

double hooke_damping_ratio(double e) {
    EFDEM_EXPECTS(e > 0 && e <= 1);
    const double l = std::log(e);
    return -l / std::sqrt(std::numbers::pi * std::numbers::pi + l * l);
}

namespace {
/// Integrates X'' = -X^1.5 - alpha X^0.25 X', X(0) = 0, X'(0) = 1 until X returns to 0.
/// Returns {rebound velocity -X'(end), duration}.
std::pair<double, double> tsuji_collision(double alpha) {
    const double h = 2e-4;
    auto acc = [alpha](double x, double v) {
        const double xp = std::max(x, 0.0);
        return -xp * std::sqrt(xp) - alpha * std::sqrt(std::sqrt(xp)) * v;
    };
    // Undamped, the contact lasts 3.2 units; with e >= kHertzRestitutionRange.lo it ends
    // before t = 20. A collision still going at t = 200 is counted as captured (no rebound).
    double x = 0, v = 1, t = 0;
    for (int step = 0; step < 1'000'000; ++step) {
        const double k1x = v, k1v = acc(x, v);
        const double k2x = v + 0.5 * h * k1v, k2v = acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v);
        const double k3x = v + 0.5 * h * k2v, k3v = acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v);
        const double k4x = v + h * k3v, k4v = acc(x + h * k3x, v + h * k3v);
        const double xn = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
        const double vn = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
        if (xn <= 0 && t > 0) {
            const double frac = x / (x - xn);  // linear interpolation of the exit time
            return {-(v + frac * (vn - v)), t + frac * h};
        }
        x = xn;
        v = vn;
        t += h;
        if (v <= 0 && x <= 0) break;
    }
    return {0.0, t};  // captured (overdamped)
}
}  // namespace

HertzDamping hertz_tsuji_damping(double e) {
    EFDEM_EXPECTS(e > 0 && e <= 1);
    if (e == 1.0) return {0.0, tsuji_collision(0.0).second};
    double lo = 0.0, hi = 1.0;
    while (tsuji_collision(hi).first > e && hi < 1e3) hi *= 2;
    for (int it = 0; it < 60 && hi - lo > 1e-10 * hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        (tsuji_collision(mid).first > e ? lo : hi) = mid;
    }
    const double alpha = 0.5 * (lo + hi);
    return {alpha, tsuji_collision(alpha).second};
}

ContactTable::ContactTable(const ContactSpec& spec, const SpeciesTable& species, Partner partner)
    : spec_(spec), n_(species.size()) {
    // Tsuji's alpha depends on e alone: solve for it once, not once per pair type.
    if (spec_.normal == NormalModel::hertz)
        hertz_ = hertz_tsuji_damping(spec_.damping == DampingModel::none ? 1.0 : spec_.restitution);
    if (partner == Partner::particle) {
        coeffs_.resize(n_ * n_);
        for (std::size_t a = 0; a < n_; ++a)
            for (std::size_t b = 0; b < n_; ++b) {
                const auto sa = static_cast<SpeciesId>(a), sb = static_cast<SpeciesId>(b);
                const double ma = species.mass(sa), mb = species.mass(sb);
                const double ra = species.radius(sa), rb = species.radius(sb);
                const auto t = derive(species[sa].name + "-" + species[sb].name,
                                      ma * mb / (ma + mb), ra * rb / (ra + rb));
                coeffs_[a * n_ + b] = t.coeffs;
                if (b >= a) info_.push_back(t);
            }
    } else {
        coeffs_.resize(n_);
        for (std::size_t a = 0; a < n_; ++a) {
            const auto sa = static_cast<SpeciesId>(a);
            const auto t = derive(species[sa].name + "-wall", species.mass(sa), species.radius(sa));
            coeffs_[a] = t.coeffs;
            info_.push_back(t);
        }
    }
}

PairTypeInfo ContactTable::derive(const std::string& label, double m_eff, double r_eff) const {
    PairTypeInfo t;
    t.label = label;
    t.m_eff = m_eff;
    ContactCoeffs& c = t.coeffs;
    c.kn = spec_.kn;
    c.kt = spec_.kt;
    c.mu = spec_.mu;
    c.r_eff = r_eff;
    if (spec_.normal == NormalModel::hooke) {
        const double omega0 = std::sqrt(spec_.kn / m_eff);
        double zeta = 0;
        switch (spec_.damping) {
            case DampingModel::restitution:
                zeta = hooke_damping_ratio(spec_.restitution);
                c.eta_n = 2 * zeta * std::sqrt(m_eff * spec_.kn);
                break;
            case DampingModel::gamma:
                c.eta_n = m_eff * spec_.gamma_n;
                zeta = c.eta_n / (2 * std::sqrt(m_eff * spec_.kn));
                break;
            case DampingModel::none:
                break;
        }
        // The time step must resolve the damping as well as the oscillation: an explicit step
        // removes the fraction dt eta_n/m_eff = 2 zeta omega0 dt of the relative velocity, and
        // beyond 2 the step overshoots and grows. With the damping time 2 pi m_eff/eta_n =
        // pi/(zeta omega0) as the time scale, dt <= time scale/5 keeps that fraction <= 1.26.
        // It is shorter than t_c only for zeta > 1/sqrt(2) (e < 0.043), where t_c diverges.
        const double damping_time =
            zeta > 0 ? std::numbers::pi / (zeta * omega0) : std::numeric_limits<double>::infinity();
        if (zeta < 1) {
            const double root = std::sqrt(1 - zeta * zeta);
            t.restitution = std::exp(-std::numbers::pi * zeta / root);
            t.contact_time = std::min(std::numbers::pi / (omega0 * root), damping_time);
        } else {  // overdamped: no rebound; the damping time bounds the time step instead
            t.restitution = 0;
            t.contact_time = damping_time;
        }
    } else {
        const HertzDamping h = hertz_;
        c.eta_n = h.alpha * std::sqrt(m_eff * spec_.kn);
        t.restitution = spec_.damping == DampingModel::none ? 1.0 : spec_.restitution;
        // Duration at v_rel = 1: tau = sqrt(m/k') L^(-1/4), L = (m/k')^(2/5), k' = kn sqrt(r_eff).
        const double kp = spec_.kn * std::sqrt(r_eff);
        const double L = std::pow(m_eff / kp, 0.4);
        t.contact_time = h.contact_time * std::sqrt(m_eff / kp) * std::pow(L, -0.25);
    }
    c.eta_t =
        spec_.tangential == TangentialModel::history ? spec_.tangential_damping * c.eta_n : 0.0;
    return t;
}

double ContactTable::min_contact_time() const {
    double t = std::numeric_limits<double>::infinity();
    for (const auto& i : info_) t = std::min(t, i.contact_time);
    return t;
}

}  // namespace efdem::dem
