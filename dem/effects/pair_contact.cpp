#include "dem/effects/pair_contact.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "dem/contact_history.hpp"
#include "dem/neighbor_list.hpp"

namespace efdem::dem {

PairContact::PairContact(const EffectSetup& s)
    : PairContact(ContactSpec::from_params(s.scope, nullptr), s.species) {}

PairContact::PairContact(const ContactSpec& spec, const SpeciesTable& species)
    : ContactEffect(spec, species, ContactTable::Partner::particle), n_species_(species.size()) {}

Needs PairContact::needs() const {
    return {.neighbor_list = true,
            .contact_history = has_history()};
}

template <class Normal, class Tangential>
void PairContact::loop(ForceContext& ctx) const {
    const auto [n, x, v, w, f, tq, rad, sp] = ctx.particles.kernel_view();
    const std::uint32_t* off = ctx.neighbors->offsets().data();
    const NeighborList::Entry* ent = ctx.neighbors->entries().data();
    const Vec3* shift = ctx.neighbors->shifts();
    Vec3* hist = nullptr;
    if constexpr (Tangential::kHistory) hist = ctx.history->pairs().data();
    const ContactCoeffs* coeffs = &table_(0, 0);
    const std::size_t ns = n_species_;
    const double dt = ctx.dt;

    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 xi = x[i], vi = v[i], wi = w[i];
        const double ri = rad[i];
        const ContactCoeffs* ci = coeffs + sp[i] * ns;
        Vec3 fi{}, ti{};
        for (std::uint32_t k = off[i]; k < off[i + 1]; ++k) {
            const NeighborList::Entry e = ent[k];
            const Index j = NeighborList::neighbor(e);
            const Vec3 d = xi - x[j] - shift[NeighborList::code(e)];
            const double rsq = norm2(d);
            const double radsum = ri + rad[j];
            if (rsq >= radsum * radsum) {
                if constexpr (Tangential::kHistory) hist[k] = Vec3{};
                continue;
            }
            const double r = std::sqrt(rsq);
            const Vec3 nrm = d * (1.0 / r);
            const ContactForce cf = contact_force<Normal, Tangential>(
                nrm, radsum - r, vi - v[j], wi * ri + w[j] * rad[j], ci[sp[j]], dt,
                Tangential::kHistory ? hist + k : nullptr);
            fi += cf.total;
            f[j] -= cf.total;
            if constexpr (Tangential::kHistory) {
                const Vec3 arm = cross(nrm, cf.tangential);
                ti -= arm * ri;
                tq[j] -= arm * rad[j];
            }
        }
        f[i] += fi;
        tq[i] += ti;
    }
}

void PairContact::add_forces(ForceContext& ctx) {
    with_contact_kernels(table_.spec(), [&](auto normal, auto tangential) {
        loop<decltype(normal), decltype(tangential)>(ctx);
    });
}

/// Calls f(i, j, k, d, radsum) for every touching listed pair.
template <class F>
static void for_each_touching(const ForceContext& ctx, F&& f) {
    const Particles& p = ctx.particles;
    const auto x = p.x();
    const auto rad = p.radius();
    const auto off = ctx.neighbors->offsets();
    const auto ent = ctx.neighbors->entries();
    const Vec3* shift = ctx.neighbors->shifts();
    for (std::size_t i = 0; i < p.size(); ++i)
        for (std::uint32_t k = off[i]; k < off[i + 1]; ++k) {
            const Index j = NeighborList::neighbor(ent[k]);
            const Vec3 d = x[i] - x[j] - shift[NeighborList::code(ent[k])];
            const double radsum = rad[i] + rad[j];
            if (norm2(d) < radsum * radsum) f(i, j, k, d, radsum);
        }
}

double PairContact::potential_energy(const ForceContext& ctx) const {
    const ContactSpec& s = table_.spec();
    const auto sp = ctx.particles.species();
    double e = 0;
    for_each_touching(ctx, [&](std::size_t i, Index j, std::uint32_t k, const Vec3& d, double radsum) {
        const ContactCoeffs& c = table_(sp[i], sp[j]);
        const double delta = radsum - norm(d);
        const bool hertz = s.normal == NormalModel::hertz;
        e += hertz ? HertzNormal::energy(c.kn, delta, c.r_eff) : HookeNormal::energy(c.kn, delta, c.r_eff);
        if (ctx.history) {
            const double scale = hertz ? HertzNormal::elastic_scale(delta, c.r_eff) : 1.0;
            e += 0.5 * scale * c.kt * norm2(ctx.history->pairs()[k]);
        }
    });
    return e;
}

void PairContact::add_thermo(const ForceContext& ctx, ThermoStats& stats) const {
    const auto tag = ctx.particles.tag();
    for_each_touching(ctx, [&](std::size_t i, Index j, std::uint32_t, const Vec3& d, double radsum) {
        ++stats.contacts;
        const double overlap = (radsum - norm(d)) / radsum;
        if (overlap > stats.max_overlap) {
            stats.max_overlap = overlap;
            stats.max_overlap_tag = tag[i];
            stats.max_overlap_partner = tag[j];
        }
    });
}



}  // namespace efdem::dem
