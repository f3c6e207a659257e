#pragma once
// A head-on binary collision (or a normal impact on the floor), measured: restitution coefficient,
// contact duration and largest overlap. Shared by the collision and stability tests.
#include <algorithm>
#include <cmath>

#include "tests/support/dem_fixtures.hpp"

namespace efdem::test {

struct Collision {
    double restitution;   ///< |normal v_rel after| / |normal v_rel before|
    double contact_time;  ///< duration of overlap, interpolated between steps
    double max_overlap;   ///< largest overlap [d_p]
};

/// Species a (left, velocity v_a along +x) meets species b (right, v_b) head-on, or, with
/// `wall`, species a falls onto the floor with speed v_a. No gravity. The spheres start `gap`
/// apart; runs until the contact has opened (at most 2e6 steps).
inline Collision head_on_collision(const dem::ContactSpec& spec, const dem::SpeciesTable& species,
                                   dem::SpeciesId a, dem::SpeciesId b, bool wall, double v_a,
                                   double v_b, double dt, double gap = 0.01) {
    using namespace efdem::dem;
    const double ra = species.radius(a), rb = species.radius(b);
    Particles p;
    if (wall) {
        p.add(1, {5, 5, ra + gap}, {0, 0, -v_a}, a, species);
    } else {
        p.add(1, {5, 5, 5}, {v_a, 0, 0}, a, species);
        p.add(2, {5 + ra + rb + gap, 5, 5}, {v_b, 0, 0}, b, species);
    }
    EffectList fx;
    if (wall)
        fx.wall(spec, species);
    else
        fx.pair(spec, species);
    System sys = make_system(species, Domain{20.0, 20.0}, std::move(p), std::move(fx), dt);
    auto overlap = [&] {
        const auto x = sys.particles().x();
        return wall ? ra - x[0].z : ra + rb - (x[1].x - x[0].x);
    };
    auto approach_speed = [&] {  // positive while approaching
        const auto v = sys.particles().v();
        return wall ? -v[0].z : v[0].x - v[1].x;
    };
    const double v_in = approach_speed();
    double t_in = -1, t_out = -1, prev = overlap(), max_overlap = 0;
    for (long s = 0; s < 2'000'000 && t_out < 0; ++s) {
        sys.step();
        const double ov = overlap();
        max_overlap = std::max(max_overlap, ov);
        if (t_in < 0 && ov > 0) t_in = sys.time() - dt * ov / (ov - prev);
        if (t_in >= 0 && ov <= 0 && prev > 0) t_out = sys.time() - dt * ov / (ov - prev);
        prev = ov;
    }
    return {-approach_speed() / v_in, t_out > 0 ? t_out - t_in : -1.0, max_overlap};
}

/// The same collision started at `phases` gaps spread over one step of approach (0.01 + k/phases
/// v dt): the contact then begins at every phase of the time step. Returns the mean restitution
/// and the largest deviation of a single collision from `e_input`.
struct PhaseAveraged {
    double mean_restitution;
    double worst_deviation;
};
inline PhaseAveraged phase_averaged_collision(const dem::ContactSpec& spec,
                                              const dem::SpeciesTable& species, dem::SpeciesId a,
                                              dem::SpeciesId b, bool wall, double v_a, double v_b,
                                              double dt, double e_input, int phases = 8) {
    const double v_rel = wall ? v_a : v_a - v_b;
    double sum = 0, worst = 0;
    for (int k = 0; k < phases; ++k) {
        const double gap = 0.01 + v_rel * dt * k / phases;
        const double e =
            head_on_collision(spec, species, a, b, wall, v_a, v_b, dt, gap).restitution;
        sum += e;
        worst = std::max(worst, std::abs(e - e_input));
    }
    return {sum / phases, worst};
}

}  // namespace efdem::test
