// Binary collisions against the closed-form linear spring-dashpot (physics.md §5.2, §12.1-2):
// restitution coefficient and contact duration for every pair type and the wall, in both
// damping conventions, and the Hertz/Tsuji variant.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "tests/support/collisions.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::dem;
using efdem::test::binary_species;
using efdem::test::paper_contact;

namespace {

using test::Collision;

/// Head-on collision at v_rel = 1 (pair: +-v/2; wall: -v onto the floor), measured with
/// dt = t_c/2000 so that the discretisation error is far below the tolerances.
Collision collide(const ContactSpec& spec, SpeciesId a, SpeciesId b, bool wall,
                  double v_rel = 1.0) {
    const double tc_estimate = 3.5e-3;
    const double v_a = wall ? v_rel : 0.5 * v_rel;
    const Collision c = test::head_on_collision(spec, binary_species(), a, b, wall, v_a,
                                                -0.5 * v_rel, tc_estimate / 2000);
    REQUIRE(c.contact_time > 0);
    return c;
}

/// Closed form for hooke with eta_n = m_eff gamma_n: e and t_c (physics.md §5.2).
std::pair<double, double> hooke_closed_form(double m_eff, double kn, double eta_n) {
    const double zeta = eta_n / (2 * std::sqrt(m_eff * kn));
    const double omega0 = std::sqrt(kn / m_eff);
    const double root = std::sqrt(1 - zeta * zeta);
    return {std::exp(-std::numbers::pi * zeta / root), std::numbers::pi / (omega0 * root)};
}

}  // namespace

TEST_CASE("head-on collisions: e = 0.9 and t_c of physics.md §5.2 for every pair type",
          "[physics][contact]") {
    // Reference values: physics.md §5.2 table (restitution convention, eta_n per pair).
    struct Case {
        SpeciesId a, b;
        bool wall;
        double tc;
    };
    const Case cases[] = {
        {0, 0, false, 3.596e-3},  // light-light
        {0, 1, false, 4.153e-3},  // light-heavy
        {1, 1, false, 5.086e-3},  // heavy-heavy
        {0, 0, true, 5.086e-3},   // light-wall
        {1, 0, true, 7.193e-3},   // heavy-wall
    };
    const ContactSpec spec = paper_contact(DampingModel::restitution, TangentialModel::none);
    for (const auto& c : cases) {
        INFO("species " << int(c.a) << " with " << (c.wall ? -1 : int(c.b)) << " (-1: the wall)");
        const Collision r = collide(spec, c.a, c.b, c.wall);
        // Issue tolerances: e within 0.002, t_c within 1 %. The reference t_c are given to 4
        // digits (rounding 1e-4 relative); dt = t_c/2000 adds ~1e-3 relative at most.
        CHECK(r.restitution == Approx(0.9).margin(0.002));
        CHECK(r.contact_time == Approx(c.tc).epsilon(0.01));
    }
}

TEST_CASE("light-light collision at v_rel = 1: maximum overlap about 1.1e-3 d",
          "[physics][contact]") {
    // physics.md §12.1: undamped bound v_rel/omega_0 = 1.14e-3; damping lowers it slightly.
    const Collision r =
        collide(paper_contact(DampingModel::restitution, TangentialModel::none), 0, 0, false);
    CHECK(r.max_overlap < 1.144e-3);
    CHECK(r.max_overlap > 1.0e-3);
}

TEST_CASE("head-on collisions with LAMMPS' single gamma_n: e = 0.900/0.885/0.862/0.810",
          "[physics][contact]") {
    // physics.md §5.2: one gamma_n = 58.5928 for all pairs gives these restitution coefficients.
    const SpeciesTable species = binary_species();
    const double m_l = species.mass(0), m_h = species.mass(1);
    struct Case {
        SpeciesId a, b;
        bool wall;
        double e_paper, m_eff;
    };
    const Case cases[] = {
        {0, 0, false, 0.900, m_l / 2}, {0, 1, false, 0.885, m_l * m_h / (m_l + m_h)},
        {1, 1, false, 0.862, m_h / 2}, {0, 0, true, 0.862, m_l},
        {1, 0, true, 0.810, m_h},
    };
    const ContactSpec spec = paper_contact(DampingModel::gamma, TangentialModel::none);
    for (const auto& c : cases) {
        INFO("m_eff " << c.m_eff);
        const Collision r = collide(spec, c.a, c.b, c.wall);
        const auto [e, tc] = hooke_closed_form(c.m_eff, spec.kn, c.m_eff * spec.gamma_n);
        CHECK(e == Approx(c.e_paper).margin(0.0006));  // the paper's values are rounded to 3 digits
        CHECK(r.restitution == Approx(e).margin(0.002));
        CHECK(r.contact_time == Approx(tc).epsilon(0.01));
    }
}

TEST_CASE("Hertz contact with Tsuji damping: e is independent of the impact velocity",
          "[physics][contact]") {
    ContactSpec spec = paper_contact(DampingModel::restitution, TangentialModel::none);
    spec.normal = NormalModel::hertz;
    spec.kn = 2e6;  // k' = kn sqrt(R_eff); a comparable stiffness at these overlaps
    for (double v : {0.25, 1.0, 4.0}) {
        INFO("v_rel = " << v);
        const Collision r = collide(spec, 0, 0, false, v);
        // The Tsuji form makes e velocity independent in the continuum; the tolerance covers the
        // time discretisation (dt = 1.75e-6 against t_c of 1e-3 .. 3e-3).
        CHECK(r.restitution == Approx(0.9).margin(0.003));
    }
}

TEST_CASE("the contact table reports the eta_n of physics.md §12.2", "[unit][contact]") {
    const ContactTable t(paper_contact(), binary_species(), ContactTable::Partner::particle);
    const ContactTable w(paper_contact(), binary_species(), ContactTable::Partner::wall);
    // physics.md §12.2, quoted to 3 decimals.
    CHECK(t(0, 0).eta_n == Approx(15.340).margin(5e-4));
    CHECK(t(0, 1).eta_n == Approx(17.713).margin(5e-4));
    CHECK(t(1, 1).eta_n == Approx(21.693).margin(5e-4));
    CHECK(w.wall(0).eta_n == Approx(21.693).margin(5e-4));
    CHECK(w.wall(1).eta_n == Approx(30.679).margin(5e-4));
    CHECK(hooke_damping_ratio(0.9) == Approx(0.0335184).margin(1e-7));
    // gamma_t = gamma_n / 2 by default, i.e. eta_t = eta_n / 2.
    CHECK(t(0, 1).eta_t == Approx(0.5 * t(0, 1).eta_n));
}

TEST_CASE("contact energy of pairs and the floor follows the normal law the forces use",
          "[unit][contact]") {
    // Two touching spheres overlapping by dp (R_eff = 1/4) high above the floor, and a third
    // pressed dw into the floor (R_eff = its radius, 1/2); no tangential spring.
    const double dp = 1e-3, dw = 2e-3, kn = 2e5;
    const SpeciesTable species = binary_species();
    for (const NormalModel law : {NormalModel::hooke, NormalModel::hertz}) {
        ContactSpec spec = paper_contact(DampingModel::restitution, TangentialModel::none);
        spec.normal = law;
        spec.kn = kn;
        Particles p;
        p.add(1, {1.0, 2.0, 3.0}, {}, 0, species);
        p.add(2, {2.0 - dp, 2.0, 3.0}, {}, 1, species);
        p.add(3, {3.0, 2.0, 0.5 - dw}, {}, 0, species);
        System s = test::make_system(
            species, Domain{5.0, 5.0}, std::move(p),
            std::move(test::EffectList{}.pair(spec, species).wall(spec, species)), 1e-5);
        const double pair = law == NormalModel::hooke ? 0.5 * kn * dp * dp
                                                      : 0.4 * kn * std::sqrt(0.25 * dp) * dp * dp;
        const double wall = law == NormalModel::hooke ? 0.5 * kn * dw * dw
                                                      : 0.4 * kn * std::sqrt(0.5 * dw) * dw * dw;
        INFO((law == NormalModel::hooke ? "hooke" : "hertz"));
        CHECK(s.potential_energy() == Approx(pair + wall).epsilon(1e-9));
    }
}
