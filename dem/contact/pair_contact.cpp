#include "dem/contact/pair_contact.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>

#include "core/cpu_dispatch.hpp"
#include "dem/contact/contact_history.hpp"
#include "dem/neighbor_list.hpp"

namespace efdem::dem {

PairContact::PairContact(const EffectSetup& s)
    : PairContact(ContactSpec::from_params(s.scope, nullptr), s.species) {}

PairContact::PairContact(const ContactSpec& spec, const SpeciesTable& species)
    : ContactEffect(spec, species, ContactTable::Partner::particle), n_species_(species.size()) {}

Needs PairContact::needs() const {
    return {.neighbor_list = true, .contact_history = has_history()};
}

namespace {

/// A listed pair of particle i found touching: entry k, partner j, separation d = x_i - x_j
/// (nearest image), |d|^2 and r_i + r_j.
struct Touching {
    std::uint32_t k;
    Index j;
    Vec3 d;
    double rsq;
    double radsum;
};

/// Partners of i per pass: the touching ones among at most this many list entries are gathered
/// first, then their forces computed (a buffer on the stack, no allocation).
constexpr std::uint32_t kChunk = 32;

/// Keeps a spring when `keep` is set and zeroes it otherwise, with bit masks: no branch.
[[gnu::always_inline]] inline void keep_or_zero(Vec3& spring, bool keep) {
    const std::uint64_t mask = std::uint64_t{0} - static_cast<std::uint64_t>(keep);
    spring = {std::bit_cast<double>(std::bit_cast<std::uint64_t>(spring.x) & mask),
              std::bit_cast<double>(std::bit_cast<std::uint64_t>(spring.y) & mask),
              std::bit_cast<double>(std::bit_cast<std::uint64_t>(spring.z) & mask)};
}

/**
 * Gathers the touching pairs among entries [k0, k1) of particle i (at xi, radius ri) into `out`
 * and returns their number. Without a branch on the distance test: a listed pair touches or not
 * about as unpredictably as a coin flip, and a mispredicted branch costs more than this whole
 * test. The spring of a pair that does not touch is zeroed (when `hist` is given).
 */
[[gnu::always_inline]] inline std::uint32_t gather_touching(const Vec3 xi, const double ri,
                                                            std::uint32_t k0, std::uint32_t k1,
                                                            const NeighborList::Entry* ent,
                                                            const Vec3* x, const double* rad,
                                                            const Vec3* shift, Vec3* hist,
                                                            Touching* out) {
    std::uint32_t m = 0;
    for (std::uint32_t k = k0; k < k1; ++k) {
        const NeighborList::Entry e = ent[k];
        const Index j = NeighborList::neighbor(e);
        const Vec3 d = xi - x[j] - shift[NeighborList::code(e)];
        const double rsq = norm2(d);
        const double radsum = ri + rad[j];
        const bool touching = !(rsq >= radsum * radsum);
        out[m] = {k, j, d, rsq, radsum};
        m += static_cast<std::uint32_t>(touching);
        if (hist) keep_or_zero(hist[k], touching);
    }
    return m;
}

}  // namespace

template <class Normal, class Tangential>
[[gnu::always_inline]] inline void PairContact::loop(ForceContext& ctx) const {
    const auto [n, x, v, w, f, tq, rad, sp] = ctx.particles.kernel_view();
    const std::uint32_t* off = ctx.neighbors->offsets().data();
    const NeighborList::Entry* ent = ctx.neighbors->entries().data();
    const Vec3* shift = ctx.neighbors->shifts();
    Vec3* hist = nullptr;
    if constexpr (Tangential::kHistory) hist = ctx.history->pairs().data();
    const ContactCoeffs* coeffs = &table_(0, 0);
    const std::size_t ns = n_species_;
    const double dt = ctx.dt;
    Touching touching[kChunk];

    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 xi = x[i], vi = v[i];
        const double ri = rad[i];
        const Vec3 wri = w[i] * ri;  // r_i w_i, the same for all partners of i
        const ContactCoeffs* ci = coeffs + sp[i] * ns;
        Vec3 fi{}, ti{};
        for (std::uint32_t k0 = off[i]; k0 < off[i + 1]; k0 += kChunk) {
            const std::uint32_t m = gather_touching(xi, ri, k0, std::min(k0 + kChunk, off[i + 1]),
                                                    ent, x, rad, shift, hist, touching);
            for (std::uint32_t c = 0; c < m; ++c) {
                const auto [k, j, d, rsq, radsum] = touching[c];
                const double r = std::sqrt(rsq);
                const Vec3 nrm = d * (1.0 / r);
                const ContactForce cf = contact_force<Normal, Tangential>(
                    nrm, radsum - r, vi - v[j], wri + w[j] * rad[j], ci[sp[j]], dt,
                    Tangential::kHistory ? hist + k : nullptr);
                fi += cf.total;
                f[j] -= cf.total;
                if constexpr (Tangential::kHistory) {
                    const Vec3 arm = cross(nrm, cf.tangential);
                    ti -= arm * ri;
                    tq[j] -= arm * rad[j];
                }
            }
        }
        f[i] += fi;
        tq[i] += ti;
    }
}

template <class Normal, class Tangential>
EFDEM_TARGET_AVX2 void PairContact::loop_avx2(ForceContext& ctx) const {
    loop<Normal, Tangential>(ctx);
}

void PairContact::add_forces(ForceContext& ctx) {
    // Same results either way (no FMA in the AVX2 build), with about 19 % fewer instructions
    // in the AVX2 one (docs/performance.md).
    const bool avx2 = cpu_has_avx2();
    with_contact_kernels(table_.spec(), [&](auto normal, auto tangential) {
        using N = decltype(normal);
        using T = decltype(tangential);
        if (avx2)
            loop_avx2<N, T>(ctx);
        else
            loop<N, T>(ctx);
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
    const auto sp = ctx.particles.species();
    return with_normal_law(table_.spec().normal, [&](auto normal) {
        double e = 0;
        for_each_touching(ctx, [&](std::size_t i, Index j, std::uint32_t k, const Vec3& d,
                                   double radsum) {
            add_contact_energy<decltype(normal)>(e, radsum - norm(d), table_(sp[i], sp[j]),
                                                 ctx.history ? &ctx.history->pairs()[k] : nullptr);
        });
        return e;
    });
}

void PairContact::add_thermo(const ForceContext& ctx, ThermoStats& stats) const {
    const auto tag = ctx.particles.tag();
    for_each_touching(ctx,
                      [&](std::size_t i, Index j, std::uint32_t, const Vec3& d, double radsum) {
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
