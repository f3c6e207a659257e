#include "coarse/dem_adapters/light_neighbours.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/contracts.hpp"

namespace efdem::coarse {

std::vector<std::uint8_t> light_neighbour_counts(const dem::Particles& particles,
                                                 const dem::Domain& box, dem::SpeciesId observed,
                                                 double reach) {
    EFDEM_EXPECTS(reach > 0.0 && box.lx > 0.0 && box.ly > 0.0);
    const std::size_t n = particles.size();
    std::vector<std::uint8_t> counts(n, 0);
    if (n == 0) return counts;
    const auto x = particles.x();
    const auto radius = particles.radius();
    const auto species = particles.species();
    const double cutoff = reach * 2.0 * *std::max_element(radius.begin(), radius.end());

    // Cells of side >= cutoff: laterally periodic, vertically from the lowest particle.
    const int nx = std::max(1, static_cast<int>(box.lx / cutoff));
    const int ny = std::max(1, static_cast<int>(box.ly / cutoff));
    double z0 = x[0].z, z1 = x[0].z;
    for (const Vec3& p : x) z0 = std::min(z0, p.z), z1 = std::max(z1, p.z);
    const int nz = std::max(1, static_cast<int>((z1 - z0) / cutoff) + 1);
    auto cell_of = [&](const Vec3& p) {
        const Vec3 w = box.wrap(p);
        const int i = std::min(nx - 1, static_cast<int>(w.x / box.lx * nx));
        const int j = std::min(ny - 1, static_cast<int>(w.y / box.ly * ny));
        const int k = std::min(nz - 1, static_cast<int>((p.z - z0) / cutoff));
        return std::array<int, 3>{std::max(0, i), std::max(0, j), k};
    };
    auto flat = [&](int i, int j, int k) {
        return (static_cast<std::size_t>(k) * ny + j) * nx + i;
    };
    // The observed particles by cell (counting sort).
    std::vector<std::size_t> start(static_cast<std::size_t>(nx) * ny * nz + 1, 0);
    std::vector<std::array<int, 3>> where(n);
    std::vector<std::size_t> cell(n);
    for (std::size_t a = 0; a < n; ++a) {
        where[a] = cell_of(x[a]);
        cell[a] = flat(where[a][0], where[a][1], where[a][2]);
        if (species[a] == observed) ++start[cell[a] + 1];
    }
    for (std::size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
    std::vector<std::size_t> members(start.back());
    {
        std::vector<std::size_t> fill(start.begin(), start.end() - 1);
        for (std::size_t a = 0; a < n; ++a)
            if (species[a] == observed) members[fill[cell[a]]++] = a;
    }
    std::vector<std::size_t> near;
    for (std::size_t a = 0; a < n; ++a) {
        const auto& c = where[a];
        // The distinct neighbour cells (a box of fewer than 3 cells wraps onto itself).
        near.clear();
        for (int dk = -1; dk <= 1; ++dk) {
            const int k = c[2] + dk;
            if (k < 0 || k >= nz) continue;
            for (int dj = -1; dj <= 1; ++dj)
                for (int di = -1; di <= 1; ++di)
                    near.push_back(flat((c[0] + di + nx) % nx, (c[1] + dj + ny) % ny, k));
        }
        std::sort(near.begin(), near.end());
        near.erase(std::unique(near.begin(), near.end()), near.end());
        int count = 0;
        for (const std::size_t q : near)
            for (std::size_t m = start[q]; m < start[q + 1]; ++m) {
                const std::size_t b = members[m];
                if (b == a) continue;
                const double reach_ab = reach * (radius[a] + radius[b]);
                const Vec3 d = box.minimum_image(x[a] - x[b]);
                if (d.x * d.x + d.y * d.y + d.z * d.z < reach_ab * reach_ab) ++count;
            }
        counts[a] = static_cast<std::uint8_t>(std::min(count, 255));
    }
    return counts;
}

}  // namespace efdem::coarse
