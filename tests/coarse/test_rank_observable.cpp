// Rank coordinates (cpi.observable = ranks): the whole-bed profile's two maps and the
// observable built on them (coarse/demixing/whole_bed_profile.hpp, rank_observable.hpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "coarse/demixing/colour_lifting.hpp"
#include "coarse/demixing/probability_grid.hpp"
#include "coarse/demixing/quantiles.hpp"
#include "coarse/demixing/rank_observable.hpp"
#include "coarse/demixing/whole_bed_profile.hpp"
#include "core/rng.hpp"

using namespace efdem::coarse;

namespace {
/// n sorted heights uniform in [lo, lo + h].
std::vector<double> sorted_heights(efdem::RandomStream& rng, std::size_t n, double lo, double h) {
    std::vector<double> z(n);
    for (double& v : z) v = rng.uniform(lo, lo + h);
    std::sort(z.begin(), z.end());
    return z;
}

/// A member: its light ICDF on the p-grid and its whole-bed profile, from its heights, half of
/// them light (every other one of a random labelling by `rng`).
struct Member {
    Eigen::VectorXd icdf, profile;
};
Member member(efdem::RandomStream& rng, const std::vector<double>& sorted,
              const ProbabilityGrid& grid) {
    std::vector<double> light;
    for (double z : sorted)
        if (rng.uniform() < 0.5 + 0.3 * (z - sorted.front()) / (sorted.back() - sorted.front()))
            light.push_back(z);  // more light particles higher up: a partly demixed bed
    Member m;
    m.icdf = quantiles_sorted(light, grid);
    m.profile.resize(kWholeBedNodes);
    m.profile[0] = sorted.front();
    m.profile.segment(1, kWholeBedNodes - 2) = quantiles_sorted(sorted, whole_bed_interior_grid());
    m.profile[kWholeBedNodes - 1] = sorted.back();
    return m;
}

/// The member with every height moved to a + b z (b > 0): a shift and an expansion of the bed.
Member moved(const Member& m, double a, double b) {
    return {(a + b * m.icdf.array()).matrix(), (a + b * m.profile.array()).matrix()};
}

/// `count` members of n heights each, member r's on [lo(r), lo(r) + h(r)]: their light ICDFs and
/// whole-bed profiles.
template <class Lo, class H>
std::pair<std::vector<Eigen::VectorXd>, std::vector<Eigen::VectorXd>> members(
    efdem::RandomStream& rng, int count, std::size_t n, Lo lo, H h) {
    std::vector<Eigen::VectorXd> icdf, profile;
    for (int r = 0; r < count; ++r) {
        const Member m = member(rng, sorted_heights(rng, n, lo(r), h(r)), ProbabilityGrid(19));
        icdf.push_back(m.icdf);
        profile.push_back(m.profile);
    }
    return {icdf, profile};
}

Eigen::MatrixXd rows(const std::vector<Eigen::VectorXd>& v) {
    Eigen::MatrixXd out(static_cast<Eigen::Index>(v.size()), v.front().size());
    for (std::size_t r = 0; r < v.size(); ++r)
        out.row(static_cast<Eigen::Index>(r)) = v[r].transpose();
    return out;
}
}  // namespace

TEST_CASE("a whole-bed profile maps heights to ranks and back exactly", "[unit][coarse]") {
    efdem::RandomStream rng(7, 0, "test");
    std::vector<double> z = sorted_heights(rng, 1000, 0.5, 15.0);
    // Ties, as in a packed layer: 30 particles at one height make a flat stretch of the map.
    std::fill(z.begin() + 400, z.begin() + 430, z[400]);
    const Member m = member(rng, z, ProbabilityGrid(19));
    const Eigen::VectorXd u = whole_bed_ranks();
    CHECK(u[0] == 0.0);
    CHECK(u[1] == Approx(0.01).epsilon(1e-15));
    CHECK(u[kWholeBedNodes - 1] == 1.0);
    // Every particle height (the ends included) goes to a rank in [0, 1] and back to itself:
    // the two linear interpolations invert each other up to rounding (1e-12 d_p on 16 d_p).
    const Eigen::VectorXd heights = Eigen::Map<const Eigen::VectorXd>(z.data(), 1000);
    const Eigen::VectorXd r = ranks_in(heights, m.profile);
    CHECK(r.minCoeff() >= 0.0);
    CHECK(r.maxCoeff() <= 1.0);
    CHECK((heights_at(r, m.profile) - heights).cwiseAbs().maxCoeff() < 1e-12);
    // Ranks are non-decreasing in height (the map is monotone), and the profile's nodes sit at
    // their own ranks (except on the flat stretch, which maps to the middle of its ranks).
    for (Eigen::Index i = 1; i < r.size(); ++i) REQUIRE(r[i] >= r[i - 1]);
    CHECK(ranks_in(Eigen::VectorXd::Constant(1, m.profile[10]), m.profile)[0] ==
          Approx(u[10]).margin(1e-12));
    // Outside the bed: clamped; NaN passes through.
    Eigen::VectorXd out(3);
    out << m.profile[0] - 1.0, m.profile[kWholeBedNodes - 1] + 1.0,
        std::numeric_limits<double>::quiet_NaN();
    const Eigen::VectorXd ro = ranks_in(out, m.profile);
    CHECK(ro[0] == 0.0);
    CHECK(ro[1] == 1.0);
    CHECK(std::isnan(ro[2]));
}

TEST_CASE("rank coordinates cancel a shift and an expansion of a member's whole bed",
          "[unit][coarse]") {
    const ProbabilityGrid grid(19);
    efdem::RandomStream rng(11, 0, "test");
    std::vector<Member> members;
    for (int r = 0; r < 4; ++r)
        members.push_back(member(rng, sorted_heights(rng, 1000, 0.5, 15.0), grid));
    std::vector<Eigen::VectorXd> icdf, profile;
    for (const Member& m : members) {
        icdf.push_back(m.icdf);
        profile.push_back(m.profile);
    }
    RankObservable obs{ProbabilityGrid(19)};
    const Eigen::VectorXd x = obs.restrict_ensemble(rows(icdf), rows(profile));
    REQUIRE(x.allFinite());
    // X is the members' mean, in d_p of the reference bed (here the first sample's mean bed):
    // close to the mean light ICDF, since the members' beds are alike.
    const Eigen::MatrixXd own = obs.restrict_members(rows(icdf), rows(profile));
    CHECK((own.colwise().mean().transpose() - x).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((x - rows(icdf).colwise().mean().transpose()).cwiseAbs().maxCoeff() < 0.5);
    // Member 1 risen by 2 d_p and expanded by 10 % (its light particles go with their bed):
    // its X is unchanged, where its ICDF moved by 2-3.5 d_p. The reference stays the first one's.
    std::vector<Eigen::VectorXd> icdf2 = icdf, profile2 = profile;
    const Member m1 = moved(members[1], 2.0, 1.1);
    icdf2[1] = m1.icdf;
    profile2[1] = m1.profile;
    const Eigen::MatrixXd own2 = obs.restrict_members(rows(icdf2), rows(profile2));
    CHECK((own2.row(1) - own.row(1)).cwiseAbs().maxCoeff() < 1e-9);
    CHECK((icdf2[1] - icdf[1]).cwiseAbs().minCoeff() > 2.0);
    // A member whose bed IS the reference bed has X = its own ICDF (the maps compose to 1).
    const Eigen::VectorXd ref =
        Eigen::Map<const Eigen::VectorXd>(obs.saved_state().data(), kWholeBedNodes);
    std::vector<Eigen::VectorXd> same_icdf{icdf[0]}, same_profile{ref};
    const Eigen::VectorXd q = heights_at(ranks_in(icdf[0], members[0].profile), ref);
    same_icdf[0] = q;
    CHECK((obs.restrict_members(rows(same_icdf), rows(same_profile)).row(0).transpose() - q)
              .cwiseAbs()
              .maxCoeff() < 1e-12);
}

TEST_CASE("a rank lift restricts back to the target it was given, in each member's own bed",
          "[unit][coarse]") {
    efdem::RandomStream rng(13, 0, "test");
    // Beds of different extents: member r stands r d_p higher.
    const auto [icdf, profile] = members(
        rng, 4, 1000, [](int r) { return 0.5 + r; }, [](int) { return 15.0; });
    RankObservable obs{ProbabilityGrid(19)};
    const Eigen::VectorXd x = obs.restrict_ensemble(rows(icdf), rows(profile));
    // A projected X: the light species 0.7 d_p higher (as a jump would move it), kept inside the
    // reference bed (a repaired X is).
    const double top = obs.saved_state()[kWholeBedNodes - 1];
    const Eigen::VectorXd target = (x.array() + 0.7).min(top - 0.1).matrix();
    std::vector<Eigen::VectorXd> lifted;
    for (std::size_t r = 0; r < 4; ++r) lifted.push_back(obs.lift_target(target, profile[r]));
    // Colour lifting leaves every height where it is, so each member's profile is unchanged: its
    // rank coordinates after a lift that meets its target exactly are the target itself.
    const Eigen::MatrixXd back = obs.restrict_members(rows(lifted), rows(profile));
    for (Eigen::Index r = 0; r < 4; ++r)
        CHECK((back.row(r).transpose() - target).cwiseAbs().maxCoeff() < 1e-9);
    // In heights the targets differ by the beds' offsets (member 3 stands 3 d_p above member 0;
    // with 1,000 heights each a bed's quantile is sampled to ~0.25 d_p, here 2.1 d_p apart at the
    // target's median), where the ICDF observable gives every member the same target.
    CHECK(lifted[3][9] - lifted[0][9] > 1.5);
}

TEST_CASE("the rank observable's reference is its state; dropped members give NaN rows",
          "[unit][coarse]") {
    efdem::RandomStream rng(17, 0, "test");
    const auto [icdf, profile] = members(
        rng, 3, 800, [](int) { return 0.5; }, [](int r) { return 12.0 + r; });
    RankObservable a{ProbabilityGrid(19)};
    CHECK(a.saved_state().empty());
    const Eigen::VectorXd x0 = a.restrict_ensemble(rows(icdf), rows(profile));
    // The reference profile, then the observed fraction (NaN: nobody told it).
    REQUIRE(static_cast<Eigen::Index>(a.saved_state().size()) == kWholeBedNodes + 1);
    CHECK(std::isnan(a.saved_state().back()));
    // A later sample of changed beds restricts through the SAME reference: a second observable
    // given the first one's state restricts it identically, one without it does not.
    std::vector<Eigen::VectorXd> later = profile;
    for (auto& p : later) p = (p.array() * 1.2).matrix();  // every bed expanded by 20 %
    RankObservable b{ProbabilityGrid(19)}, fresh{ProbabilityGrid(19)};
    b.restore_state(a.saved_state());
    const Eigen::VectorXd xa = a.restrict_ensemble(rows(icdf), rows(later));
    CHECK(b.restrict_ensemble(rows(icdf), rows(later)) == xa);
    CHECK((fresh.restrict_ensemble(rows(icdf), rows(later)) - xa).cwiseAbs().maxCoeff() > 0.1);
    (void)x0;
    // A member without data (dropped): a NaN row, the others as before.
    std::vector<Eigen::VectorXd> gone = icdf, gone_profile = profile;
    gone[1].setConstant(std::numeric_limits<double>::quiet_NaN());
    gone_profile[1].setConstant(std::numeric_limits<double>::quiet_NaN());
    const Eigen::MatrixXd own = a.restrict_members(rows(gone), rows(gone_profile));
    CHECK_FALSE(own.row(1).allFinite());
    CHECK(own.row(0).allFinite());
    CHECK(own.row(2).allFinite());
}

TEST_CASE("the rank repair keeps each interval's lights within its particles, so the lift meets X",
          "[unit][coarse][lifting]") {
    // A demixing bed: 1,000 heights, the top 400 all light, 100 more lights spread below
    // (observed fraction 0.5). The p-grid's upper nodes sit on the pure-light stretch, where the
    // lights already fill every place: u_i - 0.5 p_i is flat there.
    const ProbabilityGrid grid(19);
    efdem::RandomStream rng(23, 0, "test");
    const std::vector<double> z = sorted_heights(rng, 1000, 0.5, 15.0);
    std::vector<std::uint8_t> colour(1000, kHeavy);
    for (std::size_t j = 600; j < 1000; ++j) colour[j] = kLight;
    for (std::size_t j = 0; j < 600; j += 6) colour[j] = kLight;
    const Eigen::VectorXd profile = profile_of_heights(z);
    RankObservable obs{grid};
    obs.set_observed_fraction(0.5);
    const Eigen::VectorXd x =
        obs.restrict_ensemble(observed_icdf(z, colour, grid).transpose(), profile.transpose());
    const RepairHook repair = obs.repair_hook({});
    // The sampled state is liftable: left bit for bit (its ranks, read through the profile's
    // linear map, break the limit by up to 0.0033 of the bed between nodes: the map's resolution,
    // below the repair's threshold).
    Eigen::VectorXd same = x;
    CHECK_FALSE(repair(same).changed());
    CHECK(same == x);
    // A jump that raises the lower lights by up to 1.9 d_p and the top ones by 0.1 (as a
    // projection of a demixing bed does) squeezes the pure-light stretch: more lights than
    // places between the upper nodes.
    const Eigen::VectorXd projected = (x.array() + 2.0 * (1.0 - grid.values().array())).matrix();
    Eigen::VectorXd plain = projected;  // order and range only: the fraction unknown
    RankObservable unknown{grid};
    unknown.restrict_ensemble(observed_icdf(z, colour, grid).transpose(), profile.transpose());
    CHECK_FALSE(unknown.repair_hook({})(plain).changed());
    Eigen::VectorXd repaired = projected;
    const RepairReport report = repair(repaired);
    CHECK(report.changed());
    INFO(report.message);
    CHECK(report.message.find("more light particles") != std::string::npos);
    // In ranks the repaired X leaves room: y = u - 0.5 p non-decreasing within [0, 0.5]
    // (1e-12: the maps' rounding).
    const Eigen::VectorXd y = ranks_in(repaired, profile) - 0.5 * grid.values();
    for (Eigen::Index i = 1; i < y.size(); ++i) CHECK(y[i] >= y[i - 1] - 1e-12);
    CHECK(y[0] >= -1e-12);
    CHECK(y[y.size() - 1] <= 0.5 + 1e-12);
    // A projection onto a convex set that holds every possible state moves X nearer to each of
    // them: here the sampled one (in ranks, where the set is convex).
    const Eigen::VectorXd y_true = ranks_in(x, profile) - 0.5 * grid.values();
    const Eigen::VectorXd y_proj = ranks_in(projected, profile) - 0.5 * grid.values();
    CHECK((y - y_true).norm() <= (y_proj - y_true).norm());
    // The lift: the repaired X is met to within the particles' spacing (15 d_p / 1,000 = 0.015;
    // the at_nodes lift pins each node within the gap around its cut, 0.1 allows ~6 gaps); the
    // unrepaired one is missed by far more, the lights pushed out of the squeezed intervals.
    efdem::RandomStream a(29, 0, "lift"), b(29, 0, "lift");
    const LiftResult met = lift_colours(obs.lift_target(repaired, profile), z, colour, grid, a);
    const LiftResult missed = lift_colours(obs.lift_target(projected, profile), z, colour, grid, b);
    INFO("max deviation: repaired " << met.max_deviation << ", projected " << missed.max_deviation);
    CHECK(met.max_deviation < 0.1);
    CHECK(missed.max_deviation > 5 * met.max_deviation);
}
