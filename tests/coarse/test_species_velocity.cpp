// carry_species_velocity (cpi.relabel_velocity = species): a relabelled particle takes its new
// species' mean vertical velocity over its height band, so a lift leaves each species' local
// drift where it was; nothing else of the particles changes.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "coarse/dem_adapters/apply_colours.hpp"
#include "coarse/dem_adapters/species_velocity.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;

namespace {
constexpr dem::SpeciesId kObserved = 0, kOther = 1;  // light (colour 1), heavy (colour 0)

/// n particles at random heights in [0, 30): light ones rising at `up` + 0.01 z, heavy ones
/// sinking at `down`, each with a random horizontal velocity; every third light.
dem::System drifting_column(int n, double up, double down, double spread, std::uint32_t seed) {
    dem::Particles p = test::random_particles(n, 5.0, 0.0, 30.0, seed);
    std::mt19937 gen(seed + 1);
    std::normal_distribution<double> noise(0.0, spread);
    const auto species = test::binary_species();
    dem::Particles out;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const dem::SpeciesId s = i % 3 == 0 ? kObserved : kOther;
        const Vec3 x = p.x()[i];
        const double vz = (s == kObserved ? up + 0.01 * x.z : down) + noise(gen);
        out.add(static_cast<dem::Tag>(i + 1), x, {p.v()[i].x, p.v()[i].y, vz}, s, species);
    }
    return test::make_system(species, dem::Domain{5, 5}, std::move(out), {}, 1e-4);
}

std::vector<std::uint8_t> colours_of(const dem::System& s) {
    std::vector<std::uint8_t> c;
    for (auto id : s.particles().species()) c.push_back(id == kObserved ? 1 : 0);
    return c;
}
}  // namespace

TEST_CASE("relabelled particles take their new species' velocity; nothing else changes",
          "[coarse][lifting]") {
    // Without noise the heavies sink at one velocity and the lights rise at 0.1 + 0.01 z: a
    // relabelled particle must end at its new species' value to within the band's height
    // (200 of 100 particles per d_p: 2 d_p, 0.02 in the lights' velocity).
    dem::System s = drifting_column(3000, 0.1, -0.05, 0.0, 7);
    const std::vector<Vec3> v_before(s.particles().v().begin(), s.particles().v().end());
    std::vector<std::uint8_t> colours = colours_of(s);
    std::mt19937 gen(3);
    for (auto& c : colours)
        if (gen() % 10 == 0) c ^= 1u;  // a tenth of the labels switch
    const coarse::SpeciesVelocityShift r =
        coarse::carry_species_velocity(s, colours, kObserved, kOther);
    coarse::apply_colours(s, colours, kObserved, kOther);
    CHECK(r.shifted > 250);
    CHECK(r.kept == 0);  // every band of 200 holds ~67 lights and ~133 heavies
    const auto v = s.particles().v();
    const auto x = s.particles().x();
    const auto species = s.particles().species();
    const std::vector<std::uint8_t> before = [&] {
        std::vector<std::uint8_t> b;
        for (std::size_t i = 0; i < v_before.size(); ++i) b.push_back(i % 3 == 0 ? 1 : 0);
        return b;
    }();
    for (std::size_t i = 0; i < v.size(); ++i) {
        CHECK(v[i].x == v_before[i].x);  // horizontal velocities untouched, bit for bit
        CHECK(v[i].y == v_before[i].y);
        if (colours[i] == before[i]) {
            CHECK(v[i].z == v_before[i].z);
        } else if (species[i] == kObserved) {
            // A band's lights rise at 0.1 + 0.01 z over ~2 d_p: the band mean is within 0.02
            // of the particle's own value, the sinking heavies' 0.15 + 0.01 z below it.
            CHECK(v[i].z == Approx(0.1 + 0.01 * x[i].z).margin(0.02));
        } else {
            // Its own 0.1 + 0.01 z less the band's lights' mean plus the heavies' -0.05.
            CHECK(v[i].z == Approx(-0.05).margin(0.02));
        }
    }
}

TEST_CASE("a lift keeps each species' mean vertical velocity in noisy bands", "[coarse][lifting]") {
    // Velocities spread 0.2 around a slip of 0.15 + 0.01 z (as in the demo bed at U_s = 0.41):
    // after relabelling a tenth at random the lights' mean over the whole column is where it was
    // to a few standard errors of the mean (0.2 / sqrt(1000 lights) = 0.006: margin 0.02), while
    // keeping velocities pulls it towards the heavies' by a tenth of the slip (> 0.02).
    auto light_mean = [](const dem::System& s) {
        double sum = 0;
        int n = 0;
        for (std::size_t i = 0; i < s.particles().size(); ++i)
            if (s.particles().species()[i] == kObserved) {
                sum += s.particles().v()[i].z;
                ++n;
            }
        return sum / n;
    };
    for (const bool carry : {true, false}) {
        dem::System s = drifting_column(3000, 0.1, -0.05, 0.2, 11);
        const double before = light_mean(s);
        std::vector<std::uint8_t> colours = colours_of(s);
        std::mt19937 gen(5);
        // Switch pairs so the species counts stay: a light and a heavy of similar height.
        std::vector<std::size_t> lights, heavies;
        for (std::size_t i = 0; i < colours.size(); ++i)
            (colours[i] ? lights : heavies).push_back(i);
        for (std::size_t k = 0; k < lights.size() / 10; ++k) {
            colours[lights[10 * k]] = 0;
            colours[heavies[20 * k]] = 1;
        }
        if (carry) coarse::carry_species_velocity(s, colours, kObserved, kOther);
        coarse::apply_colours(s, colours, kObserved, kOther);
        if (carry)
            CHECK(light_mean(s) == Approx(before).margin(0.02));
        else
            CHECK(light_mean(s) < before - 0.02);
    }
}

TEST_CASE("a band with too few of a species keeps its velocities", "[coarse][lifting]") {
    // Every particle relabelled light (400 heavies switch). With bands of 200 (~67 lights and
    // ~133 heavies each) every switch is shifted; with a minimum of 150 of each species no band
    // qualifies (a mean of fewer is too noisy to move particles by): none moves, and the report
    // counts them as kept.
    dem::System s = drifting_column(600, 0.1, -0.05, 0.1, 13);
    std::vector<std::uint8_t> colours(s.particles().size(), 1);
    const std::vector<Vec3> v_before(s.particles().v().begin(), s.particles().v().end());
    const coarse::SpeciesVelocityShift r =
        coarse::carry_species_velocity(s, colours, kObserved, kOther, 200, 20);
    CHECK(r.shifted == 400);
    dem::System t = drifting_column(600, 0.1, -0.05, 0.1, 13);
    const coarse::SpeciesVelocityShift none =
        coarse::carry_species_velocity(t, colours, kObserved, kOther, 200, 150);
    CHECK(none.shifted == 0);
    CHECK(none.kept == 400);
    for (std::size_t i = 0; i < v_before.size(); ++i)
        CHECK(t.particles().v()[i].z == v_before[i].z);
}
