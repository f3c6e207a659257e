#include "dem/contact/wall_contact.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "dem/contact/contact_history.hpp"

namespace efdem::dem {

namespace {
ContactSpec wall_spec(const EffectSetup& s) {
    // Keys not given for the wall fall back to pair_contact's, when pair_contact is in the scene.
    if (s.lists("pair_contact")) {
        const Params pair = s.root.scope("pair_contact");
        return ContactSpec::from_params(s.scope, &pair);
    }
    return ContactSpec::from_params(s.scope, nullptr);
}
}  // namespace

WallContact::WallContact(const EffectSetup& s) : WallContact(wall_spec(s), s.species) {}

WallContact::WallContact(const ContactSpec& spec, const SpeciesTable& species)
    : ContactEffect(spec, species, ContactTable::Partner::wall) {}

Needs WallContact::needs() const {
    return {.contact_history = has_history()};
}

template <class Normal, class Tangential>
void WallContact::loop(ForceContext& ctx, int wall, double z_wall, double normal_sign) const {
    const auto [n, x, v, w, f, tq, rad, sp] = ctx.particles.kernel_view();
    Vec3* hist = nullptr;
    if constexpr (Tangential::kHistory) hist = ctx.history->wall(wall).data();
    const Vec3 nrm{0.0, 0.0, normal_sign};  // from the wall into the particle
    for (std::size_t i = 0; i < n; ++i) {
        const double gap = normal_sign * (x[i].z - z_wall);  // centre-to-wall distance
        const double delta = rad[i] - gap;
        if (delta <= 0) {
            if constexpr (Tangential::kHistory) hist[i] = Vec3{};
            continue;
        }
        const ContactForce cf =
            contact_force<Normal, Tangential>(nrm, delta, v[i], w[i] * rad[i], table_.wall(sp[i]),
                                              ctx.dt, Tangential::kHistory ? hist + i : nullptr);
        f[i] += cf.total;
        if constexpr (Tangential::kHistory) tq[i] -= cross(nrm, cf.tangential) * rad[i];
    }
}

void WallContact::add_forces(ForceContext& ctx) {
    with_contact_kernels(table_.spec(), [&](auto normal, auto tangential) {
        using N = decltype(normal);
        using T = decltype(tangential);
        loop<N, T>(ctx, ContactHistory::kFloor, 0.0, 1.0);
        if (ctx.domain.has_lid())
            loop<N, T>(ctx, ContactHistory::kLid, ctx.domain.lid_height, -1.0);
    });
}

double WallContact::potential_energy(const ForceContext& ctx) const {
    const auto x = ctx.particles.x();
    const auto rad = ctx.particles.radius();
    const auto sp = ctx.particles.species();
    return with_normal_law(table_.spec().normal, [&](auto normal) {
        double e = 0;
        for (std::size_t i = 0; i < x.size(); ++i) {
            const ContactCoeffs& c = table_.wall(sp[i]);
            auto add = [&](double delta, int wall) {
                if (delta <= 0) return;
                add_contact_energy<decltype(normal)>(
                    e, delta, c, ctx.history ? &ctx.history->wall(wall)[i] : nullptr);
            };
            add(rad[i] - x[i].z, ContactHistory::kFloor);
            if (ctx.domain.has_lid())
                add(rad[i] - (ctx.domain.lid_height - x[i].z), ContactHistory::kLid);
        }
        return e;
    });
}

void WallContact::add_thermo(const ForceContext& ctx, ThermoStats& stats) const {
    const auto x = ctx.particles.x();
    const auto rad = ctx.particles.radius();
    for (std::size_t i = 0; i < x.size(); ++i) {
        double delta = rad[i] - x[i].z;
        if (ctx.domain.has_lid())
            delta = std::max(delta, rad[i] - (ctx.domain.lid_height - x[i].z));
        if (delta > 0) {
            ++stats.wall_contacts;
            if (delta / (2 * rad[i]) > stats.max_overlap) {
                stats.max_overlap = delta / (2 * rad[i]);
                stats.max_overlap_tag = ctx.particles.tag()[i];
                stats.max_overlap_partner = -1;
            }
        }
    }
}

}  // namespace efdem::dem
