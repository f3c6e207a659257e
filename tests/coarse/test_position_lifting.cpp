// Position lifting (coarse/demixing/position_lifting.hpp) and the relaxation that follows it
// (dem/beds/overlap_relaxation.hpp) on loose beds of two sizes made without overlaps: the
// invariants of issue 37 item 2 (counts and mass exact, the lifted ICDF near its target, no
// overlap left after the relaxation, what the exchange injects), and the equal-size limit, in
// which exchanges are swaps and the counts are colour lifting's.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "coarse/demixing/lift_plan.hpp"
#include "coarse/demixing/position_lifting.hpp"
#include "coarse/demixing/quantiles.hpp"
#include "core/rng.hpp"
#include "dem/beds/overlap_relaxation.hpp"
#include "tests/support/dem_fixtures.hpp"

using namespace efdem;
using namespace efdem::coarse;

namespace {

const ProbabilityGrid kGrid;  // m = 19

struct Case {
    dem::Particles bed;
    std::vector<std::uint8_t> colours;  // kLight = observed
    TwoSizes sizes;
};

/// A 10 x 10 x 30 d_p loose bed: 800 small (d = 1) and 100 large (d = ratio) spheres, solid
/// fraction 0.28 at ratio 2; `observed_small` chooses which species the ICDF follows.
Case loose_case(double ratio, bool observed_small, std::uint32_t seed) {
    Case c{test::two_size_loose_bed(800, 100, ratio, 10.0, 30.0, seed), {}, {}};
    const dem::SpeciesId observed = observed_small ? 0 : 1;
    for (dem::SpeciesId s : c.bed.species()) c.colours.push_back(s == observed ? kLight : kHeavy);
    const auto table = test::two_size_species(ratio);
    c.sizes = {table[observed].diameter,
               table[1 - observed].diameter,
               table.mass(observed),
               table.mass(1 - observed),
               10.0,
               10.0};
    return c;
}

std::vector<double> observed_heights(std::span<const Vec3> x, const std::vector<std::uint8_t>& c) {
    std::vector<double> z;
    for (std::size_t j = 0; j < x.size(); ++j)
        if (c[j] == kLight) z.push_back(x[j].z);
    return z;
}

std::vector<double> all_heights(std::span<const Vec3> x) {
    std::vector<double> z;
    for (const Vec3& p : x) z.push_back(p.z);
    return z;
}

/// Largest |observed count below node i - the plan's count| over the nodes.
long count_error(std::span<const Vec3> x, const std::vector<std::uint8_t>& c,
                 const LiftPlan& plan) {
    const std::vector<double> z = observed_heights(x, c);
    long worst = 0;
    for (int i = 0; i < kGrid.size(); ++i) {
        const auto below =
            std::count_if(z.begin(), z.end(), [&](double h) { return h < plan.target[i]; });
        worst = std::max(worst, std::labs(below - plan.below[static_cast<std::size_t>(i) + 1]));
    }
    return worst;
}

double largest_overlap(const dem::Particles& p, const dem::Domain& box) {
    double worst = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        worst = std::max(worst, (p.radius()[i] - p.x()[i].z) / (2 * p.radius()[i]));
        for (std::size_t j = i + 1; j < p.size(); ++j) {
            const double reach = p.radius()[i] + p.radius()[j];
            const double d = norm(box.minimum_image(p.x()[i] - p.x()[j]));
            worst = std::max(worst, (reach - d) / reach);
        }
    }
    return worst;
}

}  // namespace

TEST_CASE("position lifting of equal sizes swaps particles and meets colour lifting's counts",
          "[lifting][positions]") {
    Case c = loose_case(1.0, true, 11);
    // Half the bed observed: alternate labels.
    for (std::size_t j = 0; j < c.colours.size(); ++j) c.colours[j] = j % 2 ? kLight : kHeavy;
    const std::vector<double> z = observed_heights(c.bed.x(), c.colours);
    Eigen::VectorXd target = quantiles(z, kGrid);
    target.array() += 3.0;  // the observed species 3 d_p higher
    RandomStream rng(5, 0, "test-lifting");
    const PositionLiftResult r =
        lift_positions(target, c.bed.x(), c.bed.v(), c.colours, c.sizes, kGrid, rng);
    REQUIRE(r.applied());
    REQUIRE(r.n_exchanges > 50);
    CHECK(r.n_moved == 2 * r.n_exchanges);
    // Every exchange a swap: the positions are a permutation of the old ones, so nothing overlaps
    // that did not before, and the solid volume of every interval is kept exactly.
    auto sorted = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v;
    };
    CHECK(sorted(all_heights(r.positions)) == sorted(all_heights(c.bed.x())));
    CHECK(r.max_volume_change == 0.0);
    // The counts below each node are the plan's exactly, as colour lifting's are.
    std::vector<double> heights = all_heights(c.bed.x());
    const LiftPlan plan = plan_lift(target, heights, c.colours, kGrid);
    CHECK(count_error(r.positions, c.colours, plan) == 0);
    // Equal masses: each swap exchanges two velocities, so momentum and energy are unchanged.
    CHECK(r.momentum_change < 1e-12);
    CHECK(std::abs(r.kinetic_energy_change) < 1e-12);
}

TEST_CASE(
    "position lifting of two sizes keeps counts and volumes, and the relaxation removes "
    "its overlaps with the heights held",
    "[lifting][positions]") {
    const bool observed_small = GENERATE(true, false);
    const double ratio = GENERATE(1.5, 2.0);
    CAPTURE(observed_small, ratio);
    Case c = loose_case(ratio, observed_small, 23);
    const dem::Domain box{10.0, 10.0};
    REQUIRE(largest_overlap(c.bed, box) <= 0.0);
    const std::vector<double> z = observed_heights(c.bed.x(), c.colours);
    const Eigen::VectorXd now = quantiles(z, kGrid);
    // The observed species demixes: its middle nodes move by up to 1.5 d_p, up for the small
    // species, down for the large (size segregation's direction), its ends stay.
    Eigen::VectorXd target = now;
    for (int i = 0; i < kGrid.size(); ++i)
        target[i] += (observed_small ? 1.5 : -1.5) * std::sin(M_PI * kGrid.p(i));
    RandomStream colour_rng(7, 0, "test-lifting");
    const LiftResult colour =
        lift_colours(target, all_heights(c.bed.x()), c.colours, kGrid, colour_rng);
    RandomStream rng(7, 0, "test-lifting");
    const PositionLiftResult r =
        lift_positions(target, c.bed.x(), c.bed.v(), c.colours, c.sizes, kGrid, rng);
    REQUIRE(r.applied());
    const std::vector<double> heights = all_heights(c.bed.x());
    const LiftPlan plan = plan_lift(target, heights, c.colours, kGrid);
    const double rho = std::pow(ratio, 3);
    // Each exchange lands a whole group of ~rho small particles around one place (or a large
    // particle where a group was), so a node's observed count can be off the plan's by at most
    // one group and the rounding of its size; measured 1-4.
    CHECK(count_error(r.positions, c.colours, plan) <= std::ceil(rho) + 1);
    // The same for the solid volume of an interval, in small volumes: about a large particle
    // (rho) on each side of a cut (measured 0.9-8 with the count plan; 6.9 = 2.04 rho with the
    // large species observed, whose moved spheres sit at the cuts, so a group that takes one's
    // place straddles a cut).
    CHECK(r.max_volume_change <= 3 * rho);
    // As near the target as colour lifting gets with the same heights, up to where the groups
    // land: each moved particle lies within R_L - r_S of the place it took (measured: within
    // 0.07 d_p of colour lifting's deviation, which is 0.31-0.57 d_p here).
    CHECK(r.max_deviation <= colour.max_deviation + 0.5 * ratio);
    CHECK(r.n_exchanges >= 6);
    // The large species observed, each moved sphere goes to its rank's height and every other
    // lies within the resolution of its own: every node within the resolution (0.1 d_p) of the
    // target, where colour lifting's counts leave it 0.31-0.57 d_p off (the gaps between the
    // 100 large spheres' heights).
    if (!observed_small) CHECK(r.max_deviation <= c.sizes.resolution + 1e-12);
    // Ratio 2, the large species observed: every group holds exactly 8 small spheres of the
    // large one's mass, so momentum and kinetic energy are kept to rounding.
    if (ratio == 2.0 && !observed_small) {
        CHECK(r.momentum_change < 1e-12);
        CHECK(std::abs(r.kinetic_energy_change) < 1e-12);
    }

    dem::Particles lifted = c.bed;
    std::copy(r.positions.begin(), r.positions.end(), lifted.x().begin());
    // The exchange leaves overlaps of most of a small diameter (measured 0.83-0.89 of the
    // pair's mean diameter): far beyond the watchdog's 0.1, so the relaxation is needed.
    CHECK(largest_overlap(lifted, box) > 0.5);
    dem::OverlapRelaxationSettings settings;
    const dem::OverlapRelaxationReport rep = dem::relax_overlaps(lifted, box, settings);
    INFO("iterations " << rep.iterations << ", overlap left " << rep.max_overlap_after);
    CHECK(rep.converged);
    CHECK(largest_overlap(lifted, box) <= settings.tolerance * (1 + 1e-9));
    CHECK(rep.max_height_change <= settings.height_band + 1e-12);
    // Every height moved by at most the band, so every quantile did (quantiles are 1-Lipschitz
    // in the largest height change): the relaxation keeps the coarse variable where the lift
    // put it to within 0.25 d_p.
    const Eigen::VectorXd relaxed = quantiles(observed_heights(lifted.x(), c.colours), kGrid);
    CHECK((relaxed - r.achieved_icdf).cwiseAbs().maxCoeff() <= settings.height_band + 1e-12);
    // Particles and their species are untouched: the same count of each, the same masses.
    CHECK(std::equal(lifted.species().begin(), lifted.species().end(), c.bed.species().begin()));
}

TEST_CASE("position lifting refuses a target it cannot use and moves nothing",
          "[lifting][positions]") {
    Case c = loose_case(2.0, true, 5);
    Eigen::VectorXd target = quantiles(observed_heights(c.bed.x(), c.colours), kGrid);
    target[3] = std::numeric_limits<double>::quiet_NaN();
    RandomStream rng(1, 0, "test-lifting");
    const PositionLiftResult r =
        lift_positions(target, c.bed.x(), c.bed.v(), c.colours, c.sizes, kGrid, rng);
    CHECK_FALSE(r.applied());
    CHECK(r.n_moved == 0);
    CHECK(std::equal(r.positions.begin(), r.positions.end(), c.bed.x().begin()));
    CHECK_THAT(r.message, Catch::Matchers::Contains("no particle moved"));
}
