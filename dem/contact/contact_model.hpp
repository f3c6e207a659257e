#pragma once
/// \file
/// ContactModel: the scene's choice of contact sub-models (normal / damping / tangential, after
/// LAMMPS GRANULAR) and the coefficient table derived from it for every pair type.
///
/// Scene keys, in the scope of the effect (`pair_contact.` or `wall_contact.`):
///
// clang-format off
/// | key                  | meaning                                              | default          |
/// |----------------------|------------------------------------------------------|------------------|
/// | normal               | `hooke` or `hertz`                                   | hooke            |
/// | kn                   | normal stiffness [rho_s g d_p^2] (hertz: per d_p^0.5)| required         |
/// | damping              | `restitution` (eta_n per pair, e exact for every     | restitution      |
/// |                      | pair) or `gamma` (LAMMPS: one gamma_n for all pairs, |                  |
/// |                      | eta_n = m_eff gamma_n; hooke only) or `none`         |                  |
/// | restitution          | coefficient of restitution e in (0, 1]               | required if      |
/// |                      |                                                      | damping = restitution |
/// | gamma_n              | damping per unit effective mass [1/time]             | required if gamma |
/// | tangential           | `history` (spring + dashpot + Coulomb) or `none`     | history          |
/// | kt                   | tangential stiffness                                 | 2/7 kn           |
/// | tangential_damping   | eta_t / eta_n (LAMMPS: gamma_t = gamma_n / 2)        | 0.5              |
/// | mu                   | Coulomb friction coefficient                         | required if history |
// clang-format on
///
/// wall_contact reads the same keys; each key it does not set falls back to pair_contact's
/// value when pair_contact is in the scene ("the same sub-models drive particle-floor contact").

#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "dem/contact/contact_laws.hpp"
#include "dem/species.hpp"

namespace efdem {
class Params;
}

namespace efdem::dem {

/// Restitution allowed with normal = hertz. Tsuji's damping constant is found by simulating a
/// collision; below e = 0.01 the rebound takes very long to come and the search is slow.
inline const Bounds kHertzRestitutionRange = Bounds::closed(0.01, 1.0);

enum class NormalModel { hooke, hertz };
enum class DampingModel { restitution, gamma, none };
enum class TangentialModel { none, history };

struct ContactSpec {
    NormalModel normal = NormalModel::hooke;
    DampingModel damping = DampingModel::restitution;
    TangentialModel tangential = TangentialModel::history;
    double kn = 0;
    double kt = 0;
    double restitution = 1;
    double gamma_n = 0;
    double tangential_damping = 0.5;
    double mu = 0;

    /// Reads the keys of the table above from `scope`; keys missing there are read from
    /// `fallback` when it is given (wall_contact falling back to pair_contact).
    static ContactSpec from_params(const Params& scope, const Params* fallback);
};

/// Derived numbers of one pair type, for `efdem --check` and the time-step limit.
struct PairTypeInfo {
    std::string label;       ///< "light-heavy", "light-wall"
    double m_eff = 0;        ///< effective mass [rho_s d_p^3]
    ContactCoeffs coeffs;    ///< what the kernel uses
    double restitution = 1;  ///< resulting e (0 when overdamped)
    /// Time scale the time step must resolve [sqrt(d_p/g)]: the duration of a head-on contact
    /// (hertz: at v_rel = 1), or for hooke the damping time 2 pi m_eff/eta_n when that is
    /// shorter (zeta > 1/sqrt(2), e < 0.043; overdamped contacts never end).
    double contact_time = 0;
};

/// Hooke: damping ratio zeta for restitution e, zeta = -ln e / sqrt(pi^2 + ln^2 e) (§5.2).
double hooke_damping_ratio(double e);
/// Hertz with Tsuji damping: the alpha with eta_n = alpha sqrt(m_eff kn) that gives
/// restitution e, and the dimensionless contact duration; solved numerically (RK4 + bisection).
struct HertzDamping {
    double alpha;
    double contact_time;  ///< in units of tau = sqrt(m/k') L^(-1/4), L = (v^2 m/k')^(2/5)
};
HertzDamping hertz_tsuji_damping(double e);

/**
 * \brief Coefficients for every species pair (or every species against a wall).
 *
 * \code
 * ContactTable table(spec, species, ContactTable::Partner::particle);
 * const ContactCoeffs& c = table(si, sj);
 * \endcode
 */
class ContactTable {
  public:
    enum class Partner { particle, wall };
    ContactTable(const ContactSpec& spec, const SpeciesTable& species, Partner partner);

    const ContactCoeffs& operator()(SpeciesId a, SpeciesId b) const { return coeffs_[a * n_ + b]; }
    const ContactCoeffs& wall(SpeciesId a) const { return coeffs_[a]; }
    const std::vector<PairTypeInfo>& info() const { return info_; }
    /// Shortest contact duration over all pair types.
    double min_contact_time() const;
    const ContactSpec& spec() const { return spec_; }

  private:
    PairTypeInfo derive(const std::string& label, double m_eff, double r_eff) const;

    ContactSpec spec_;
    HertzDamping hertz_{};  ///< Tsuji damping for hertz (depends only on e)
    std::size_t n_;
    std::vector<ContactCoeffs> coeffs_;
    std::vector<PairTypeInfo> info_;
};

/// Calls f(Normal{}) with the kernel type of the normal law (HookeNormal, HertzNormal) and
/// returns what f returns: the one place where the run-time NormalModel becomes a compile-time
/// type. Force loops (with_contact_kernels), contact energies and reports all go through it;
/// call it once per loop, never per pair.
/// \code double e = with_normal_law(spec.normal, [&](auto n) { return decltype(n)::energy(kn,
/// delta, r); }); \endcode
template <class F>
decltype(auto) with_normal_law(NormalModel normal, F&& f) {
    if (normal == NormalModel::hertz) return f(HertzNormal{});
    return f(HookeNormal{});
}

/// Calls f(Normal{}, Tangential{}) with the kernel types of the spec's sub-models (the normal
/// law through with_normal_law): one dispatch per loop, never per pair.
/// \code with_contact_kernels(spec, [&](auto n, auto t) { loop<decltype(n), decltype(t)>(); });
/// \endcode
template <class F>
void with_contact_kernels(const ContactSpec& spec, F&& f) {
    const bool history = spec.tangential == TangentialModel::history;
    with_normal_law(spec.normal, [&](auto normal) {
        if (history)
            f(normal, HistoryTangential{});
        else
            f(normal, NoTangential{});
    });
}

}  // namespace efdem::dem
