#include "dem/beds/overlap_relaxation.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/contracts.hpp"
#include "dem/neighbor_list.hpp"

namespace efdem::dem {

namespace {

/// Largest overlap fraction of the floor and the lid for a particle at z of radius r.
double wall_overlap(double z, double r, const Domain& domain, double& push) {
    push = 0;
    double worst = 0;
    if (z < r) {
        push += r - z;
        worst = (r - z) / (2 * r);
    }
    if (domain.has_lid() && z + r > domain.lid_height) {
        push -= z + r - domain.lid_height;
        worst = std::max(worst, (z + r - domain.lid_height) / (2 * r));
    }
    return worst;
}

}  // namespace

OverlapRelaxationReport relax_overlaps(Particles& p, const Domain& domain,
                                       const OverlapRelaxationSettings& settings) {
    EFDEM_EXPECTS(settings.tolerance > 0 && settings.height_band >= 0);
    OverlapRelaxationReport report;
    const std::size_t n = p.size();
    if (n == 0) {
        report.converged = true;
        return report;
    }
    double max_diameter = 0;
    for (double r : p.radius()) max_diameter = std::max(max_diameter, 2 * r);
    // A copy in cell order for the list; `original[i]` is the index in `p` of copy particle i.
    Particles q = p;
    std::vector<Index> original(n), new_to_old;
    for (std::size_t i = 0; i < n; ++i) original[i] = static_cast<Index>(i);
    const double skin = 0.3 * max_diameter;
    NeighborList list(max_diameter, skin);
    std::vector<Vec3> start(p.x().begin(), p.x().end());
    std::vector<Vec3> push(n);
    std::vector<int> contacts(n);

    for (long it = 0;; ++it) {
        if (list.needs_rebuild(q)) {
            list.build(q, domain, new_to_old);
            std::vector<Index> o(n);
            for (std::size_t i = 0; i < n; ++i) o[i] = original[new_to_old[i]];
            original.swap(o);
        }
        const auto x = q.x();
        const auto radius = q.radius();
        const auto off = list.offsets();
        const auto ent = list.entries();
        const Vec3* shift = list.shifts();
        std::fill(push.begin(), push.end(), Vec3{});
        std::fill(contacts.begin(), contacts.end(), 0);
        double worst = 0;
        for (std::size_t i = 0; i < n; ++i) {
            for (std::uint32_t k = off[i]; k < off[i + 1]; ++k) {
                const Index j = NeighborList::neighbor(ent[k]);
                const Vec3 d = x[i] - x[j] - shift[NeighborList::code(ent[k])];
                const double reach = radius[i] + radius[j];
                const double r2 = norm2(d);
                if (r2 >= reach * reach) continue;
                const double r = std::sqrt(r2);
                const double delta = reach - r;
                worst = std::max(worst, delta / reach);  // reach = the pair's mean diameter
                // Coincident centres (r = 0): push along z, the one direction that keeps x, y.
                const Vec3 normal = r > 0 ? d * (1.0 / r) : Vec3{0, 0, 1};
                push[i] += normal * delta;
                push[j] -= normal * delta;
                ++contacts[i];
                ++contacts[j];
            }
            double wall = 0;
            worst = std::max(worst, wall_overlap(x[i].z, radius[i], domain, wall));
            if (wall != 0) {
                push[i].z += wall;
                ++contacts[i];
            }
        }
        if (it == 0) report.max_overlap_before = worst;
        report.max_overlap_after = worst;
        report.iterations = it;
        if (worst <= settings.tolerance) {
            report.converged = true;
            break;
        }
        if (it == settings.max_iterations) break;
        for (std::size_t i = 0; i < n; ++i) {
            if (contacts[i] == 0) continue;
            x[i] += push[i] * (0.5 / contacts[i]);
            const double z0 = start[original[i]].z;
            x[i].z = std::clamp(x[i].z, z0 - settings.height_band, z0 + settings.height_band);
        }
    }

    const auto x = q.x();
    auto out = p.x();
    for (std::size_t i = 0; i < n; ++i) {
        const Index o = original[i];
        const Vec3 moved = domain.minimum_image(x[i] - start[o]);
        out[o] = start[o] + moved;
        report.max_displacement = std::max(report.max_displacement, norm(moved));
        report.max_height_change = std::max(report.max_height_change, std::abs(moved.z));
    }
    return report;
}

}  // namespace efdem::dem
