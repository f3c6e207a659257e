#include "dem/neighbor_list.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/contracts.hpp"
#include "core/error.hpp"

namespace efdem::dem {

NeighborList::NeighborList(double max_diameter, double skin)
    : max_diameter_(max_diameter), skin_(skin), cutoff_(max_diameter + skin) {
    EFDEM_EXPECTS(max_diameter > 0 && skin >= 0);
}

bool NeighborList::needs_rebuild(const Particles& p) const {
    if (x_build_.size() != p.size() || builds_ == 0) return true;
    const double limit = 0.25 * skin_ * skin_;  // (skin/2)^2
    const Vec3* x = p.x().data();
    const Vec3* x0 = x_build_.data();
    const std::size_t n = p.size();
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i) worst = std::max(worst, norm2(x[i] - x0[i]));
    return worst > limit;
}

void NeighborList::bin(const Particles& p, const Domain& domain, std::span<const Vec3> x) {
    const std::size_t n = p.size();
    double z_lo = 0.0, z_hi = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        if (!all_finite(x[i]))
            throw RuntimeFailure("particle " + std::to_string(p.tag()[i]) +
                                 " has a non-finite position: the simulation has blown up");
        z_lo = i == 0 ? x[i].z : std::min(z_lo, x[i].z);
        z_hi = i == 0 ? x[i].z : std::max(z_hi, x[i].z);
    }
    if (!std::isfinite(z_hi - z_lo))
        throw RuntimeFailure(
            "particles span an impossible height range: the simulation has blown up");
    // Cells at least `cutoff` wide in each direction (so that the 27 neighbouring cells hold
    // every partner), counted in doubles: a wide box or a tall, sparse column must not overflow
    // an int or allocate far more cells than particles. If the grid would exceed 2 n + 4096 cells,
    // its largest dimension is halved until it fits; coarser cells only cost extra distance
    // tests, the list is the same.
    double cells[3] = {std::max(1.0, std::floor(domain.lx / cutoff_)),
                       std::max(1.0, std::floor(domain.ly / cutoff_)),
                       std::floor((z_hi - z_lo) / cutoff_) + 1.0};
    const double budget = 2.0 * static_cast<double>(n) + 4096.0;
    EFDEM_ASSERT(std::isfinite(cells[0] * cells[1]));
    while (cells[0] * cells[1] * cells[2] > budget) {
        double& largest = *std::max_element(cells, cells + 3);
        largest = std::max(1.0, std::floor(0.5 * largest));
    }
    nx_ = static_cast<int>(cells[0]);
    ny_ = static_cast<int>(cells[1]);
    nz_ = static_cast<int>(cells[2]);
    cell_x_ = domain.lx / nx_;
    cell_y_ = domain.ly / ny_;
    cell_z_ = std::max(cutoff_, (z_hi - z_lo) / nz_);
    z_lo_ = z_lo;
    const std::size_t ncell = static_cast<std::size_t>(nx_) * ny_ * nz_;
    cell_of_.resize(n);
    cell_start_.assign(ncell + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const int cx = std::clamp(static_cast<int>(x[i].x / cell_x_), 0, nx_ - 1);
        const int cy = std::clamp(static_cast<int>(x[i].y / cell_y_), 0, ny_ - 1);
        const int cz = std::clamp(static_cast<int>((x[i].z - z_lo_) / cell_z_), 0, nz_ - 1);
        const auto c = static_cast<std::uint32_t>((cz * ny_ + cy) * nx_ + cx);
        cell_of_[i] = c;
        ++cell_start_[c + 1];
    }
    std::partial_sum(cell_start_.begin(), cell_start_.end(), cell_start_.begin());
}

void NeighborList::build(Particles& p, const Domain& domain, std::vector<Index>& new_to_old) {
    const std::size_t n = p.size();
    if (n >= kMaxParticles)
        throw RuntimeFailure("too many particles for the neighbour list (limit 2^28)");
    if (domain.lx < 2 * cutoff_ || domain.ly < 2 * cutoff_)
        throw RuntimeFailure("the periodic box is narrower than twice the neighbour cutoff");
    auto x = p.x();
    for (auto& xi : x) xi = domain.wrap(xi);
    bin(p, domain, x);
    // Counting sort by cell (stable: equal cells keep their order, so sorting a sorted set is
    // the identity, which restarts rely on).
    new_to_old.resize(n);
    std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) new_to_old[fill[cell_of_[i]]++] = static_cast<Index>(i);
    p.permute(new_to_old);
    std::vector<std::uint32_t> sorted_cells(n);
    for (std::size_t k = 0; k < n; ++k) sorted_cells[k] = cell_of_[new_to_old[k]];
    cell_of_.swap(sorted_cells);
    build_pairs(p, domain, p.x());
    x_build_.assign(p.x().begin(), p.x().end());
}

void NeighborList::rebuild_from_reference(const Particles& p, const Domain& domain,
                                          std::span<const Vec3> reference) {
    EFDEM_EXPECTS(reference.size() == p.size());
    bin(p, domain, reference);
    build_pairs(p, domain, reference);
    x_build_.assign(reference.begin(), reference.end());
}

void NeighborList::build_pairs(const Particles& p, const Domain& domain, std::span<const Vec3> x) {
    const std::size_t n = p.size();
    for (int sx = -1; sx <= 1; ++sx)
        for (int sy = -1; sy <= 1; ++sy)
            shifts_[(sx + 1) * 3 + (sy + 1)] = Vec3{sx * domain.lx, sy * domain.ly, 0.0};

    // Particles of a cell, in index order. After build() the arrays are sorted by cell, so this
    // is a contiguous range; after rebuild_from_reference() they are not, so use a bucket list.
    std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    std::vector<Index> members(n);
    for (std::size_t i = 0; i < n; ++i) members[fill[cell_of_[i]]++] = static_cast<Index>(i);

    const double half_lx = 0.5 * domain.lx, half_ly = 0.5 * domain.ly;
    const double* radius = p.radius().data();
    offsets_.assign(n + 1, 0);
    entries_.clear();
    entries_.reserve(n * 6);
    int stencil[27];
    for (std::size_t i = 0; i < n; ++i) {
        offsets_[i] = static_cast<std::uint32_t>(entries_.size());
        const std::uint32_t c = cell_of_[i];
        const int cx = static_cast<int>(c % static_cast<std::uint32_t>(nx_));
        const int cy = static_cast<int>((c / static_cast<std::uint32_t>(nx_)) %
                                        static_cast<std::uint32_t>(ny_));
        const int cz = static_cast<int>(c / static_cast<std::uint32_t>(nx_ * ny_));
        // Unique neighbour cells (periodic in x and y; fewer than 3 cells means duplicates).
        int ns = 0;
        for (int dz = -1; dz <= 1; ++dz) {
            const int zz = cz + dz;
            if (zz < 0 || zz >= nz_) continue;
            for (int dy = -1; dy <= 1; ++dy) {
                const int yy = (cy + dy + ny_) % ny_;
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = (cx + dx + nx_) % nx_;
                    const int cell = (zz * ny_ + yy) * nx_ + xx;
                    if (std::find(stencil, stencil + ns, cell) == stencil + ns)
                        stencil[ns++] = cell;
                }
            }
        }
        std::sort(stencil, stencil + ns);
        const Vec3 xi = x[i];
        const double ri = radius[i];
        for (int s = 0; s < ns; ++s) {
            const auto cell = static_cast<std::size_t>(stencil[s]);
            for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
                const Index j = members[k];
                if (j <= i) continue;
                Vec3 d = xi - x[j];
                int sx = 0, sy = 0;
                if (d.x > half_lx)
                    sx = 1;
                else if (d.x < -half_lx)
                    sx = -1;
                if (d.y > half_ly)
                    sy = 1;
                else if (d.y < -half_ly)
                    sy = -1;
                d.x -= sx * domain.lx;
                d.y -= sy * domain.ly;
                const double reach = ri + radius[j] + skin_;
                if (norm2(d) < reach * reach)
                    entries_.push_back((j << kCodeBits) |
                                       static_cast<Entry>((sx + 1) * 3 + (sy + 1)));
            }
        }
        // Keep each particle's neighbours in index order: contact history lookup and the force
        // loop then walk memory forward.
        std::sort(entries_.begin() + offsets_[i], entries_.end());
    }
    offsets_[n] = static_cast<std::uint32_t>(entries_.size());
    ++builds_;
}

std::size_t NeighborList::bytes() const {
    return offsets_.capacity() * sizeof(std::uint32_t) + entries_.capacity() * sizeof(Entry) +
           x_build_.capacity() * sizeof(Vec3) + cell_of_.capacity() * sizeof(std::uint32_t) +
           cell_start_.capacity() * sizeof(std::uint32_t);
}

}  // namespace efdem::dem
