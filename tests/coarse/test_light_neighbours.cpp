// light_neighbour_counts (cpi.relabel = clustered): each particle's count of observed particles
// within 1.15 contact distances, through the periodic sides, against a direct count of every pair.
#include <catch2/catch.hpp>

#include <cstdint>
#include <random>
#include <vector>

#include "coarse/dem_adapters/light_neighbours.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;

namespace {
/// Every pair, nearest periodic image: the count light_neighbour_counts must give.
std::vector<std::uint8_t> brute_force(const dem::Particles& p, const dem::Domain& box,
                                      dem::SpeciesId observed, double reach) {
    std::vector<std::uint8_t> out(p.size(), 0);
    for (std::size_t a = 0; a < p.size(); ++a)
        for (std::size_t b = 0; b < p.size(); ++b) {
            if (a == b || p.species()[b] != observed) continue;
            const Vec3 d = box.minimum_image(p.x()[a] - p.x()[b]);
            const double r = reach * (p.radius()[a] + p.radius()[b]);
            if (d.x * d.x + d.y * d.y + d.z * d.z < r * r) ++out[a];
        }
    return out;
}

/// n spheres of diameters 1 and `big` (every third big, every second observed) at random in a
/// box of side l and height h, some of them outside [0, l) laterally (not yet wrapped).
dem::Particles bed(int n, double l, double h, double big, std::uint32_t seed) {
    const dem::SpeciesTable species({{"light", 1.0, 1.0}, {"heavy", 2.0, big}});
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> ux(-0.5 * l, 1.5 * l), uz(0.0, h);
    dem::Particles p;
    for (int i = 0; i < n; ++i)
        p.add(i + 1, {ux(gen), ux(gen), uz(gen)}, {}, i % 2 == 0 ? 0 : 1, species);
    return p;
}
}  // namespace

TEST_CASE("light-neighbour counts equal a count over every pair", "[unit][coarse][lifting]") {
    // A box of 5 d_p holds two cells of 2.3 a side (each wraps onto the other's neighbours: counted
    // once), 12 d_p five; diameters 1 and 1.6 (the cutoff follows the larger); dense enough that
    // most particles have neighbours (mean count 1-4), so a miss or a double count shows.
    for (const double l : {5.0, 12.0})
        for (const double big : {1.0, 1.6}) {
            INFO("box " << l << ", larger diameter " << big);
            const dem::Domain box{l, l};
            const dem::Particles p = bed(static_cast<int>(l * l * 8), l, 10.0, big, 11);
            const auto counts = coarse::light_neighbour_counts(p, box, 0);
            const auto expected = brute_force(p, box, 0, coarse::kNeighbourReach);
            CHECK(counts == expected);
            long total = 0;
            for (auto c : expected) total += c;
            CHECK(total > static_cast<long>(p.size()));  // not a test of empty neighbourhoods
        }
}

TEST_CASE("light-neighbour counts: no particle, one particle", "[unit][coarse][lifting]") {
    const dem::Domain box{5, 5};
    CHECK(coarse::light_neighbour_counts(dem::Particles{}, box, 0).empty());
    const dem::Particles one = bed(1, 5.0, 1.0, 1.0, 3);
    CHECK(coarse::light_neighbour_counts(one, box, 0) == std::vector<std::uint8_t>{0});
}
