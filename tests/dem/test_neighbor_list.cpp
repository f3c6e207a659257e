// Neighbour list against a brute-force N^2 oracle (Cabana style), across periodic images, and
// contact history carried through rebuilds and the spatial sort that comes with them.
#include <catch2/catch.hpp>

#include <algorithm>
#include <limits>
#include <map>
#include <set>

#include "core/rng.hpp"
#include "dem/contact/contact_history.hpp"
#include "dem/neighbor_list.hpp"
#include "tests/support/dem_fixtures.hpp"
#include "tests/support/fp_traps.hpp"

using namespace efdem;
using namespace efdem::dem;

namespace {
using PairSet = std::set<std::pair<Tag, Tag>>;

/// All pairs (by tag, smaller first) closer than r_i + r_j + skin for the nearest image.
PairSet oracle(const Particles& p, const Domain& d, double skin) {
    PairSet out;
    for (std::size_t i = 0; i < p.size(); ++i)
        for (std::size_t j = i + 1; j < p.size(); ++j) {
            const Vec3 dx = d.minimum_image(p.x()[i] - p.x()[j]);
            const double reach = p.radius()[i] + p.radius()[j] + skin;
            if (norm2(dx) < reach * reach)
                out.emplace(std::min(p.tag()[i], p.tag()[j]), std::max(p.tag()[i], p.tag()[j]));
        }
    return out;
}

PairSet listed(const NeighborList& list, const Particles& p, const Domain& d) {
    PairSet out;
    for (std::size_t i = 0; i < p.size(); ++i)
        for (auto k = list.offsets()[i]; k < list.offsets()[i + 1]; ++k) {
            const auto e = list.entries()[k];
            const Index j = NeighborList::neighbor(e);
            // The stored image must be the nearest one.
            const Vec3 dx = p.x()[i] - p.x()[j] - list.shifts()[NeighborList::code(e)];
            REQUIRE(norm2(dx) == Approx(norm2(d.minimum_image(p.x()[i] - p.x()[j]))));
            const auto key =
                std::make_pair(std::min(p.tag()[i], p.tag()[j]), std::max(p.tag()[i], p.tag()[j]));
            REQUIRE(out.insert(key).second);  // each pair listed once
        }
    return out;
}

Particles random_particles(int n, double lx, double ly, double lz, std::uint64_t seed) {
    const SpeciesTable species({{"small", 1, 0.8}, {"big", 1, 1.2}});
    RandomStream rng(seed, 0, "test");
    Particles p;
    for (int k = 0; k < n; ++k)
        p.add(k + 1, {rng.uniform(0, lx), rng.uniform(0, ly), rng.uniform(0, lz)}, {},
              static_cast<SpeciesId>(rng.below(2)), species);
    return p;
}
}  // namespace

TEST_CASE("the neighbour list equals the N^2 oracle on dense and dilute random sets",
          "[unit][neighbor]") {
    struct Case {
        int n;
        double lx, ly, lz;
    };
    // Dense (overlapping, ~1.5 per unit volume), dilute, and a box only 2.5 cutoffs wide (two
    // cells per direction: the stencil holds duplicate cells that must be removed).
    const Case cases[] = {{2000, 10, 10, 12}, {300, 12, 9, 30}, {400, 3.5, 3.2, 20}};
    for (const auto& c : cases) {
        for (std::uint64_t seed = 1; seed <= 3; ++seed) {
            Particles p = random_particles(c.n, c.lx, c.ly, c.lz, seed);
            const Domain d{c.lx, c.ly};
            NeighborList list(1.2, 0.15);
            std::vector<Index> perm;
            list.build(p, d, perm);
            INFO("n " << c.n << " box " << c.lx << " seed " << seed);
            CHECK(listed(list, p, d) == oracle(p, d, 0.15));
        }
    }
}

TEST_CASE("the spatial sort is a permutation that keeps every particle's data together",
          "[unit][neighbor]") {
    Particles p = random_particles(500, 8, 8, 8, 4);
    std::vector<std::pair<Tag, Vec3>> before;
    for (std::size_t i = 0; i < p.size(); ++i) before.emplace_back(p.tag()[i], p.x()[i]);
    NeighborList list(1.2, 0.1);
    std::vector<Index> perm;
    list.build(p, Domain{8, 8}, perm);
    for (std::size_t k = 0; k < p.size(); ++k) {
        REQUIRE(p.tag()[k] == before[perm[k]].first);
        REQUIRE(p.x()[k] == before[perm[k]].second);
    }
    // Sorting a sorted set again is the identity (restarts rely on it).
    list.build(p, Domain{8, 8}, perm);
    for (std::size_t k = 0; k < p.size(); ++k) REQUIRE(perm[k] == k);
}

TEST_CASE("rebuild_from_reference reproduces the list of the last build exactly",
          "[unit][neighbor]") {
    Particles p = random_particles(800, 9, 9, 9, 5);
    const Domain d{9, 9};
    NeighborList a(1.2, 0.1);
    std::vector<Index> perm;
    a.build(p, d, perm);
    NeighborList b(1.2, 0.1);
    b.rebuild_from_reference(p, d, a.reference_positions());
    REQUIRE(
        std::equal(a.offsets().begin(), a.offsets().end(), b.offsets().begin(), b.offsets().end()));
    REQUIRE(
        std::equal(a.entries().begin(), a.entries().end(), b.entries().begin(), b.entries().end()));
}

TEST_CASE("contact history survives rebuilds and sorting, attached to the same particle pair",
          "[unit][neighbor][history]") {
    // A sheared dense packing with friction: many persistent contacts. Record the springs by tag
    // pair, force a rebuild (with its re-sort), and compare.
    const SpeciesTable species = test::binary_species();
    RandomStream rng(2, 0, "test");
    Particles p;
    const int nside = 8;
    for (int a = 0; a < nside; ++a)
        for (int b = 0; b < nside; ++b)
            for (int c = 0; c < nside; ++c)
                p.add(static_cast<Tag>(p.size() + 1),
                      {0.98 * a + 0.49 + 0.01 * rng.uniform(), 0.98 * b + 0.49, 0.98 * c + 0.6},
                      {0.1 * rng.normal(), 0.1 * rng.normal(), 0.1 * rng.normal()},
                      static_cast<SpeciesId>(rng.below(2)), species);
    test::EffectList fx;
    fx.pair(test::paper_contact(), species);
    System sys =
        test::make_system(species, {0.98 * nside, 0.98 * nside}, std::move(p), std::move(fx), 1e-4);
    sys.run(200);  // springs build up
    auto springs = [&] {
        std::map<std::pair<Tag, Tag>, Vec3> out;
        for (const auto& r :
             sys.contact_history()->export_pairs(*sys.neighbor_list(), sys.particles())) {
            if (r.tag_i < r.tag_j)
                out[{r.tag_i, r.tag_j}] = r.xi;
            else
                out[{r.tag_j, r.tag_i}] = -r.xi;
        }
        return out;
    };
    const auto before = springs();
    REQUIRE(before.size() > 100);
    const long builds = sys.neighbor_list()->builds();
    // Translate the whole packing (the geometry of every pair is unchanged) so that most
    // particles change cell and the rebuild's sort really permutes them.
    for (auto& x : sys.particles().x()) x += Vec3{1.3, 0.7, 0.0};
    const std::vector<Tag> order_before(sys.particles().tag().begin(), sys.particles().tag().end());
    sys.rebuild_neighbors();
    const std::vector<Tag> order_after(sys.particles().tag().begin(), sys.particles().tag().end());
    REQUIRE(order_after != order_before);
    REQUIRE(sys.neighbor_list()->builds() == builds + 1);
    CHECK(springs() == before);
}

TEST_CASE("wide sparse boxes and tall sparse columns: a bounded cell grid, the oracle's list",
          "[unit][neighbor]") {
    // Cells are >= the cutoff wide; a grid with a cell per cutoff would have 8e11 cells in a
    // 1e6 x 1e6 box (an int overflow and terabytes), or 5e5 cells for two particles 5e5 apart.
    // The grid is coarsened to at most 2 n + 4096 cells: memory O(n), list unchanged.
    const SpeciesTable species({{"small", 1, 0.8}, {"big", 1, 1.2}});
    struct Case {
        double lx, ly;
        std::vector<Vec3> x;
    };
    const Case cases[] = {
        {1e6, 1e6, {{0.5, 0.5, 0.5}, {1.3, 0.6, 0.5}, {999'999.7, 0.5, 0.5}, {5e5, 5e5, 3}}},
        {4, 4, {{1, 1, 0.5}, {1, 1, 5e5}, {1.9, 1.2, 5e5 + 0.4}, {3.8, 1, 0.5}}},
        {1e6, 3, {{1, 1, 1}, {1e6 - 0.1, 1, 1.3}, {1.7, 1, 1}}},
    };
    for (const auto& c : cases) {
        Particles p;
        for (const auto& x : c.x)
            p.add(static_cast<Tag>(p.size() + 1), x, {}, static_cast<SpeciesId>(p.size() % 2),
                  species);
        const Domain d{c.lx, c.ly};
        NeighborList list(1.2, 0.15);
        std::vector<Index> perm;
        list.build(p, d, perm);
        INFO("box " << c.lx << " x " << c.ly);
        CHECK(listed(list, p, d) == oracle(p, d, 0.15));
        CHECK(!listed(list, p, d).empty());  // each case has a close pair (some across the seam)
        // cell_start_ holds one entry per cell (+1): at most 2 n + 4097 of them.
        CHECK(list.bytes() < 64 * 1024);
    }
}

TEST_CASE("a non-finite position stops the rebuild with a runtime failure", "[unit][neighbor]") {
    // A blown-up state must not reach the cell binning (a NaN converted to int is undefined).
    efdem::test::FpTrapsOff no_traps;  // making the NaN is the point
    Particles p = random_particles(20, 5, 5, 5, 1);
    p.x()[7].z = std::numeric_limits<double>::quiet_NaN();
    NeighborList list(1.2, 0.1);
    std::vector<Index> perm;
    CHECK_THROWS_AS(list.build(p, Domain{5, 5}, perm), RuntimeFailure);
}
