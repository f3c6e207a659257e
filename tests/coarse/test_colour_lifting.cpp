// Colour lifting (physics.md §9): recolouring to a target light ICDF, random (minimal change) and
// node-aware (at_nodes). Property tests on random beds of 10 to 1e5 particles, identities,
// determinism, and infeasible targets. Interval bookkeeping here is done independently of the
// implementation (std::upper_bound and plain counting).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <numeric>
#include <vector>

#include "coarse/demixing/colour_lifting.hpp"
#include "coarse/demixing/quantiles.hpp"
#include "core/rng.hpp"

using namespace efdem::coarse;
using Labels = std::vector<std::uint8_t>;

namespace {
const ProbabilityGrid kGrid;  // m = 19

struct Bed {
    std::vector<double> z;  // heights [d_p], distinct with probability 1
    Labels colour;
    long n_light() const { return std::count(colour.begin(), colour.end(), kLight); }
};

/// Uniform heights in a 50 d_p bed, labels light with probability f (at least one of each).
Bed random_bed(efdem::RandomStream& rng, std::size_t n, double f) {
    Bed bed{std::vector<double>(n), Labels(n)};
    for (std::size_t j = 0; j < n; ++j) {
        bed.z[j] = rng.uniform(0.5, 50.0);
        bed.colour[j] = rng.uniform() < f ? kLight : kHeavy;
    }
    bed.colour[0] = kLight;
    bed.colour[1] = kHeavy;
    return bed;
}

std::vector<double> light_heights(const Bed& bed, const Labels& colour) {
    std::vector<double> z;
    for (std::size_t j = 0; j < bed.z.size(); ++j)
        if (colour[j] == kLight) z.push_back(bed.z[j]);
    return z;
}

/// Another labelling with the same number of lights, partly demixed (lights prefer the top):
/// the n_light particles with the highest z/50 + noise.
Labels demixed_labels(efdem::RandomStream& rng, const Bed& bed, double noise) {
    std::vector<std::pair<double, std::size_t>> score;
    for (std::size_t j = 0; j < bed.z.size(); ++j)
        score.push_back({bed.z[j] / 50.0 + noise * rng.uniform(), j});
    std::sort(score.begin(), score.end(), std::greater<>());
    Labels s(bed.z.size(), kHeavy);
    const auto n_light = static_cast<std::size_t>(bed.n_light());
    for (std::size_t i = 0; i < n_light; ++i) s[score[i].second] = kLight;
    return s;
}

/// The interval of height z among the cuts: 0 below the first, cuts.size() above the last.
std::size_t interval_of(const Eigen::VectorXd& cuts, double z) {
    return static_cast<std::size_t>(std::upper_bound(cuts.data(), cuts.data() + cuts.size(), z) -
                                    cuts.data());
}

/// Light particles per interval I_0..I_m of the cuts (interval = number of cuts <= z).
std::vector<long> interval_light_counts(const Bed& bed, const Labels& colour,
                                        const Eigen::VectorXd& cuts) {
    std::vector<long> count(static_cast<std::size_t>(cuts.size()) + 1, 0);
    for (std::size_t j = 0; j < bed.z.size(); ++j)
        if (colour[j] == kLight) ++count[interval_of(cuts, bed.z[j])];
    return count;
}

/// The beds of the like_lights and keep_clusters cases: random (half light), the target its light
/// ICDF 0.5 d_p higher (a CPI jump's move: each interval of ~100 particles switches ~10), and
/// light-neighbour counts uniform on 6..12 (mean 9) for the lights, 0..12 (mean 6) for the heavies.
struct CountedBed {
    Bed bed;
    Eigen::VectorXd target;
    Labels counts;
};

CountedBed counted_bed(efdem::RandomStream& rng) {
    CountedBed c{random_bed(rng, 2000, 0.5), {}, {}};
    c.target = (quantiles(light_heights(c.bed, c.bed.colour), kGrid).array() + 0.5).matrix();
    c.counts.resize(c.bed.z.size());
    for (std::size_t j = 0; j < c.bed.z.size(); ++j)
        c.counts[j] =
            static_cast<std::uint8_t>(c.bed.colour[j] == kLight ? 6 + rng.below(7) : rng.below(13));
    return c;
}

long differing(const Labels& a, const Labels& b) {
    return std::inner_product(a.begin(), a.end(), b.begin(), 0L, std::plus<>(),
                              std::not_equal_to<>());
}
}  // namespace

TEST_CASE("lifting to a realizable target: counts, minimality, §9 step 5", "[unit][coarse]") {
    // The target is the ICDF of another labelling S with the same number of lights, so it is
    // feasible by construction and S itself has the interval counts the lifting must reach.
    // Relabel::random: the fewest switches (the node-aware default is tested below).
    efdem::RandomStream rng(30, 0, "test-lifting");
    for (std::size_t n : {10u, 31u, 100u, 1000u, 10000u, 100000u}) {
        for (int trial = 0; trial < (n <= 1000 ? 20 : 3); ++trial) {
            const Bed bed = random_bed(rng, n, rng.uniform(0.05, 0.95));
            const Labels s = demixed_labels(rng, bed, rng.uniform(0.05, 1.0));
            const Eigen::VectorXd target = quantiles(light_heights(bed, s), kGrid);
            efdem::RandomStream lifting(31, trial, "lifting");
            const LiftResult res =
                lift_colours(target, bed.z, bed.colour, kGrid, lifting, {}, Relabel::random);
            INFO("n = " << n << ", N_L = " << bed.n_light() << ": " << res.message);
            REQUIRE(res.status == LiftStatus::ok);
            // Species counts exactly invariant; n_changed is what changed.
            REQUIRE(std::count(res.colours.begin(), res.colours.end(), kLight) == bed.n_light());
            REQUIRE(static_cast<long>(res.n_changed) == differing(bed.colour, res.colours));
            // Every interval ends with S's count, with exactly sum |c_k - n_k| switches (the
            // least any relabelling with these counts needs), hence no more than S needs.
            const auto before = interval_light_counts(bed, bed.colour, res.target);
            const auto wanted = interval_light_counts(bed, s, res.target);
            REQUIRE(interval_light_counts(bed, res.colours, res.target) == wanted);
            long needed = 0;
            for (std::size_t k = 0; k < wanted.size(); ++k)
                needed += std::abs(before[k] - wanted[k]);
            REQUIRE(static_cast<long>(res.n_changed) == needed);
            REQUIRE(static_cast<long>(res.n_changed) <= differing(bed.colour, s));
            // The reported ICDF is the restriction of the new labels (same order statistics,
            // same arithmetic: exact), and each node is within the spacing of the light heights
            // around its cut: between the highest light below z*_i and the lowest at or above.
            const auto lights = light_heights(bed, res.colours);
            REQUIRE(res.achieved_icdf == quantiles(lights, kGrid));
            for (int i = 0; i < kGrid.size(); ++i) {
                const double cut = res.target[i];
                double lo = cut, hi = std::numeric_limits<double>::infinity();
                for (double v : lights) {
                    if (v < cut)
                        lo = std::max(lo == cut ? v : lo, v);
                    else
                        hi = std::min(hi, v);
                }
                REQUIRE(std::abs(res.achieved_icdf[i] - cut) <= hi - lo);
            }
        }
    }
}

namespace {
/// The gap of all the particles (either species) around `cut`: from the highest below it to
/// the lowest at or above it (infinite when the cut is beyond every particle).
double gap_around(const std::vector<double>& z, double cut) {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    for (double v : z) {
        if (v < cut)
            lo = std::max(lo, v);
        else
            hi = std::min(hi, v);
    }
    return hi - lo;
}
}  // namespace

TEST_CASE("at_nodes: every node within the gap of all particles around its cut", "[unit][coarse]") {
    // Feasible targets (another labelling's ICDF) on beds with >= 10 lights per interval, so
    // each node is defined by the top light of the interval below its cut and the bottom light
    // of the one above (or one of them): both are pinned, and the pair of particles flanking
    // the cut is among the candidates, so no node can miss by more than that pair's gap. The
    // random relabelling only guarantees the lights' gap (test above), here ~2x wider. Same
    // counts per interval, species count invariant, n_changed what changed.
    efdem::RandomStream rng(36, 0, "test-lifting");
    double sum_nodes = 0.0, sum_random = 0.0;
    for (std::size_t n : {1000u, 10000u}) {
        for (int trial = 0; trial < 10; ++trial) {
            const Bed bed = random_bed(rng, n, rng.uniform(0.3, 0.7));
            const Labels s = demixed_labels(rng, bed, rng.uniform(0.05, 1.0));
            const Eigen::VectorXd target = quantiles(light_heights(bed, s), kGrid);
            efdem::RandomStream a(37, trial, "lifting"), b(37, trial, "lifting");
            const LiftResult res = lift_colours(target, bed.z, bed.colour, kGrid, a);
            const LiftResult random =
                lift_colours(target, bed.z, bed.colour, kGrid, b, {}, Relabel::random);
            INFO("n = " << n << ", trial " << trial << ": " << res.message);
            REQUIRE(res.status == LiftStatus::ok);
            CHECK(std::count(res.colours.begin(), res.colours.end(), kLight) == bed.n_light());
            CHECK(static_cast<long>(res.n_changed) == differing(bed.colour, res.colours));
            CHECK(interval_light_counts(bed, res.colours, res.target) ==
                  interval_light_counts(bed, s, res.target));
            CHECK(res.achieved_icdf == quantiles(light_heights(bed, res.colours), kGrid));
            for (int i = 0; i < kGrid.size(); ++i)
                CHECK(std::abs(res.achieved_icdf[i] - res.target[i]) <=
                      gap_around(bed.z, res.target[i]));
            sum_nodes += (res.achieved_icdf - res.target).squaredNorm();
            sum_random += (random.achieved_icdf - random.target).squaredNorm();
        }
    }
    // The bound above allows up to the full gap; measured, the best of ~100 candidate pairs
    // meets a node far closer: RMS at_nodes / random 0.009 over these 20 lifts.
    CHECK(std::sqrt(sum_nodes / sum_random) < 0.1);
}

TEST_CASE("at_nodes: a short interval's excess lands next to its cut", "[unit][coarse]") {
    // The top two cuts squeezed into the bed's top 1.8 d_p, which holds fewer particles than
    // the light count above the lower one (as on the demo bed's first jump,
    // docs/accuracy_vs_cost.md): no lift meets node 17, and the plan moves the excess lights
    // below its cut. At_nodes pins node 17's ranks as high as the room allows: with D observed
    // particles above them in their interval, the node is no lower than the (D + 2)-th highest
    // particle below the cut. The random relabelling spreads the excess over the interval:
    // measured 3x farther (sum over 10 beds 6.9 d_p against 19.6).
    efdem::RandomStream rng(38, 0, "test-lifting");
    double err_nodes = 0.0, err_random = 0.0;
    for (int trial = 0; trial < 10; ++trial) {
        const Bed bed = random_bed(rng, 2000, 0.5);
        Eigen::VectorXd target = quantiles(light_heights(bed, bed.colour), kGrid);
        const double z_max = *std::max_element(bed.z.begin(), bed.z.end());
        target[17] = z_max - 1.8;  // ~73 particles above, ~100 lights wanted
        target[18] = z_max - 0.9;  // ~36 particles above, ~50 lights wanted
        efdem::RandomStream a(39, trial, "lifting"), b(39, trial, "lifting");
        const LiftResult res = lift_colours(target, bed.z, bed.colour, kGrid, a);
        const LiftResult random =
            lift_colours(target, bed.z, bed.colour, kGrid, b, {}, Relabel::random);
        INFO("trial " << trial << ": " << res.message);
        REQUIRE(res.status == LiftStatus::adjusted);
        REQUIRE(res.n_short_intervals >= 1);
        CHECK(std::count(res.colours.begin(), res.colours.end(), kLight) == bed.n_light());
        const double cut = res.target[17];
        std::vector<double> below_cut;
        long lights_below = 0;
        for (std::size_t j = 0; j < bed.z.size(); ++j)
            if (bed.z[j] < cut) {
                below_cut.push_back(bed.z[j]);
                lights_below += res.colours[j] == kLight;
            }
        std::sort(below_cut.begin(), below_cut.end(), std::greater<>());
        const NodeRank r = node_rank(kGrid, 17, bed.n_light());
        const long above_ranks = lights_below - 1 - (r.lower + 1);  // D
        REQUIRE(above_ranks >= 0);
        CHECK(res.achieved_icdf[17] >= below_cut[static_cast<std::size_t>(above_ranks) + 1]);
        err_nodes += std::abs(res.achieved_icdf[17] - cut);
        err_random += std::abs(random.achieved_icdf[17] - random.target[17]);
    }
    CHECK(err_nodes < 0.5 * err_random);
}

TEST_CASE("at_nodes with moving flags: still particles switch no more than at random",
          "[unit][coarse]") {
    // As above (a still lower half, 20 % of it moving). A node's pin takes a still particle
    // only if it is already light (or nothing else is in reach), and the runs between pins draw
    // the moving ones first. Against the random relabelling with the same flags: the same
    // counts; still labels switched at most 5 % more (the pins add at most two switches per node,
    // 38 against ~750 per lift here; measured 5681 against 5650 over 20 beds); the nodes, which
    // must now be met with moving or light particles, still at most half as far off (measured:
    // sum of max deviations 0.81 d_p against 2.61; without flags 0.0013).
    efdem::RandomStream rng(40, 0, "test-lifting");
    long still_nodes = 0, still_random = 0;
    double off_nodes = 0.0, off_random = 0.0;
    for (int trial = 0; trial < 20; ++trial) {
        const Bed bed = random_bed(rng, 2000, 0.5);
        const Labels s = demixed_labels(rng, bed, 0.5);
        const Eigen::VectorXd target = quantiles(light_heights(bed, s), kGrid);
        Labels moving(bed.z.size());
        for (std::size_t j = 0; j < bed.z.size(); ++j)
            moving[j] = bed.z[j] > 25.0 || rng.uniform() < 0.2 ? 1 : 0;
        efdem::RandomStream a(41, trial, "lifting"), b(41, trial, "lifting");
        const SwitchOrder order{SwitchOrder::By::moving, moving};
        const LiftResult nodes = lift_colours(target, bed.z, bed.colour, kGrid, a, order);
        const LiftResult random =
            lift_colours(target, bed.z, bed.colour, kGrid, b, order, Relabel::random);
        INFO("trial " << trial);
        REQUIRE(nodes.status == LiftStatus::ok);
        CHECK(interval_light_counts(bed, nodes.colours, nodes.target) ==
              interval_light_counts(bed, random.colours, random.target));
        for (std::size_t j = 0; j < bed.z.size(); ++j)
            if (!moving[j]) {
                still_nodes += nodes.colours[j] != bed.colour[j];
                still_random += random.colours[j] != bed.colour[j];
            }
        off_nodes += nodes.max_deviation;
        off_random += random.max_deviation;
    }
    CHECK(still_nodes <= 1.05 * static_cast<double>(still_random));
    CHECK(off_nodes < 0.5 * off_random);
}

TEST_CASE("light_neighbours order: heavies among lights turn light, lone lights turn heavy",
          "[unit][coarse]") {
    // Each particle carries a light-neighbour count (0..12, random). With the random relabelling
    // (Relabel::random, no pins) every interval must switch, of the colour it has too many of,
    // the particles its order prefers: a heavy turned light has at least as many light
    // neighbours as any heavy of its interval left heavy; a light turned heavy at most as many as
    // any light kept. The counts per interval, and so n_changed, are those of the unordered lift.
    efdem::RandomStream rng(50, 0, "test-lifting");
    for (int trial = 0; trial < 10; ++trial) {
        const Bed bed = random_bed(rng, 2000, 0.5);
        const Labels s = demixed_labels(rng, bed, 0.5);
        const Eigen::VectorXd target = quantiles(light_heights(bed, s), kGrid);
        Labels neighbours(bed.z.size());
        for (auto& c : neighbours) c = static_cast<std::uint8_t>(rng.below(13));
        efdem::RandomStream a(51, trial, "lifting"), b(51, trial, "lifting");
        const LiftResult ordered = lift_colours(
            target, bed.z, bed.colour, kGrid, a,
            SwitchOrder{SwitchOrder::By::light_neighbours, neighbours}, Relabel::random);
        const LiftResult plain =
            lift_colours(target, bed.z, bed.colour, kGrid, b, {}, Relabel::random);
        INFO("trial " << trial);
        REQUIRE(ordered.status == LiftStatus::ok);
        CHECK(ordered.n_changed == plain.n_changed);
        CHECK(ordered.n_changed > 200);  // a demixing target: hundreds of switches to order
        CHECK(interval_light_counts(bed, ordered.colours, ordered.target) ==
              interval_light_counts(bed, plain.colours, plain.target));
        // Per interval: the fewest neighbours among heavies turned light, the most among heavies
        // kept; the reverse for lights.
        const auto m = static_cast<std::size_t>(ordered.target.size()) + 1;
        std::vector<int> turned_light_min(m, 99), kept_heavy_max(m, -1);
        std::vector<int> turned_heavy_max(m, -1), kept_light_min(m, 99);
        const Eigen::VectorXd& cuts = ordered.target;
        for (std::size_t j = 0; j < bed.z.size(); ++j) {
            const std::size_t k = interval_of(cuts, bed.z[j]);
            const int c = neighbours[j];
            if (bed.colour[j] != kLight && ordered.colours[j] == kLight)
                turned_light_min[k] = std::min(turned_light_min[k], c);
            if (bed.colour[j] != kLight && ordered.colours[j] != kLight)
                kept_heavy_max[k] = std::max(kept_heavy_max[k], c);
            if (bed.colour[j] == kLight && ordered.colours[j] != kLight)
                turned_heavy_max[k] = std::max(turned_heavy_max[k], c);
            if (bed.colour[j] == kLight && ordered.colours[j] == kLight)
                kept_light_min[k] = std::min(kept_light_min[k], c);
        }
        for (std::size_t k = 0; k < m; ++k) {
            INFO("interval " << k);
            CHECK(turned_light_min[k] >= kept_heavy_max[k]);
            CHECK(turned_heavy_max[k] <= kept_light_min[k]);
        }
    }
}

TEST_CASE(
    "like_lights order: the new lights' light-neighbour counts are distributed as the lights'",
    "[unit][coarse]") {
    // The beds of counted_bed (lights' counts mean 9, heavies' 6, the target 0.5 d_p higher). A
    // random draw of heavies gives new lights of mean 6; like_lights weights a
    // heavy of count c by P_light(c) / P_heavy(c), ~0 below 6 and equal above: its draws are
    // uniform on 6..12, mean 9, less what drawing without replacement takes where an interval
    // has few such heavies to spare (measured: 8.92 against the lights' 9.00, random 6.23; 0.7
    // is the margin). The lights turned heavy: a uniform sample of the lights, mean 9 within 0.7
    // as well. Relabel::random: with at_nodes the nodes' pins (2 per node, here a third of the
    // switches) are chosen by height, not count.
    efdem::RandomStream rng(52, 0, "test-lifting");
    double drawn = 0.0, random = 0.0, lights = 0.0, removed = 0.0;
    long n_drawn = 0, n_random = 0, n_lights = 0, n_removed = 0;
    for (int trial = 0; trial < 10; ++trial) {
        const auto [bed, target, counts] = counted_bed(rng);
        efdem::RandomStream a(53, trial, "lifting"), b(53, trial, "lifting");
        const LiftResult like =
            lift_colours(target, bed.z, bed.colour, kGrid, a,
                         SwitchOrder{SwitchOrder::By::like_lights, counts}, Relabel::random);
        const LiftResult plain =
            lift_colours(target, bed.z, bed.colour, kGrid, b, {}, Relabel::random);
        REQUIRE(like.status == LiftStatus::ok);
        CHECK(interval_light_counts(bed, like.colours, like.target) ==
              interval_light_counts(bed, plain.colours, plain.target));
        for (std::size_t j = 0; j < bed.z.size(); ++j) {
            if (bed.colour[j] == kLight) lights += counts[j], ++n_lights;
            if (bed.colour[j] != kLight && like.colours[j] == kLight) drawn += counts[j], ++n_drawn;
            if (bed.colour[j] == kLight && like.colours[j] != kLight)
                removed += counts[j], ++n_removed;
            if (bed.colour[j] != kLight && plain.colours[j] == kLight)
                random += counts[j], ++n_random;
        }
    }
    REQUIRE(n_drawn > 400);  // 40+ switches per lift: the means below are to ~0.15
    INFO("new lights' mean count: like_lights "
         << drawn / n_drawn << ", random " << random / n_random << "; lights " << lights / n_lights
         << ", removed " << removed / n_removed);
    CHECK(random / n_random == Approx(6.0).margin(0.4));
    CHECK(drawn / n_drawn == Approx(lights / n_lights).margin(0.7));
    CHECK(removed / n_removed == Approx(lights / n_lights).margin(0.7));
}

TEST_CASE("keep_clusters order: new lights as like_lights, the lone lights removed first",
          "[unit][coarse]") {
    // The beds of counted_bed, as in the like_lights case. Against like_lights with the same
    // stream: the same counts; the lights turned heavy are, in each run of particles, those with
    // the fewest light neighbours (no light kept has fewer than one removed from its interval),
    // and the new lights' mean count stays the lights' within 0.7.
    efdem::RandomStream rng(52, 0, "test-lifting");
    double drawn = 0.0, lights = 0.0;
    long n_drawn = 0, n_lights = 0;
    for (int trial = 0; trial < 10; ++trial) {
        const auto [bed, target, counts] = counted_bed(rng);
        efdem::RandomStream a(53, trial, "lifting"), b(53, trial, "lifting");
        const LiftResult keep =
            lift_colours(target, bed.z, bed.colour, kGrid, a,
                         SwitchOrder{SwitchOrder::By::keep_clusters, counts}, Relabel::random);
        const LiftResult like =
            lift_colours(target, bed.z, bed.colour, kGrid, b,
                         SwitchOrder{SwitchOrder::By::like_lights, counts}, Relabel::random);
        REQUIRE(keep.status == LiftStatus::ok);
        CHECK(interval_light_counts(bed, keep.colours, keep.target) ==
              interval_light_counts(bed, like.colours, like.target));
        const auto m = static_cast<std::size_t>(keep.target.size()) + 1;
        std::vector<int> removed_max(m, -1), kept_min(m, 99);
        const Eigen::VectorXd& cuts = keep.target;
        for (std::size_t j = 0; j < bed.z.size(); ++j) {
            const std::size_t k = interval_of(cuts, bed.z[j]);
            if (bed.colour[j] == kLight) {
                lights += counts[j], ++n_lights;
                if (keep.colours[j] == kLight)
                    kept_min[k] = std::min<int>(kept_min[k], counts[j]);
                else
                    removed_max[k] = std::max<int>(removed_max[k], counts[j]);
            } else if (keep.colours[j] == kLight) {
                drawn += counts[j], ++n_drawn;
            }
        }
        for (std::size_t k = 0; k < m; ++k) CHECK(removed_max[k] <= kept_min[k]);
    }
    REQUIRE(n_drawn > 400);
    CHECK(drawn / n_drawn == Approx(lights / n_lights).margin(0.7));
}

TEST_CASE("a target equal to the current ICDF changes no label", "[unit][coarse]") {
    efdem::RandomStream rng(32, 0, "test-lifting");
    for (std::size_t n : {10u, 31u, 100u, 1000u, 10000u, 100000u}) {
        const Bed bed = random_bed(rng, n, rng.uniform(0.05, 0.95));
        const Eigen::VectorXd current = quantiles(light_heights(bed, bed.colour), kGrid);
        for (const Relabel relabel : {Relabel::at_nodes, Relabel::random}) {
            const LiftResult res =
                lift_colours(current, bed.z, bed.colour, kGrid, rng, {}, relabel);
            INFO("n = " << n << ", N_L = " << bed.n_light() << ", "
                        << (relabel == Relabel::random ? "random" : "at_nodes"));
            CHECK(res.status == LiftStatus::ok);
            CHECK(res.n_changed == 0);
            CHECK(res.colours == bed.colour);
            CHECK(res.max_deviation == 0.0);
        }
    }
}

TEST_CASE("lifting is deterministic for a given random stream", "[unit][coarse]") {
    efdem::RandomStream rng(33, 0, "test-lifting");
    const Bed bed = random_bed(rng, 5000, 0.5);
    const Eigen::VectorXd target =
        quantiles(light_heights(bed, demixed_labels(rng, bed, 0.3)), kGrid);
    efdem::RandomStream a(7, 3, "lifting"), b(7, 3, "lifting"), other(7, 4, "lifting");
    const LiftResult first = lift_colours(target, bed.z, bed.colour, kGrid, a);
    const LiftResult again = lift_colours(target, bed.z, bed.colour, kGrid, b);
    const LiftResult elsewhere = lift_colours(target, bed.z, bed.colour, kGrid, other);
    REQUIRE(first.n_changed > 100);
    CHECK(again.colours == first.colours);
    CHECK(a.state() == b.state());
    // Another stream picks other particles, in the same numbers per interval.
    CHECK(elsewhere.colours != first.colours);
    CHECK(interval_light_counts(bed, elsewhere.colours, target) ==
          interval_light_counts(bed, first.colours, target));
}

TEST_CASE("infeasible lifting targets are rejected or clipped, with a message", "[unit][coarse]") {
    efdem::RandomStream rng(34, 0, "test-lifting");
    const Bed bed = random_bed(rng, 2000, 0.4);
    const Eigen::VectorXd current = quantiles(light_heights(bed, bed.colour), kGrid);
    const double z_max = *std::max_element(bed.z.begin(), bed.z.end());
    // After any applied lift, whatever the target, the invariants hold.
    auto check_invariants = [&](const LiftResult& res) {
        CHECK(std::count(res.colours.begin(), res.colours.end(), kLight) == bed.n_light());
        CHECK(static_cast<long>(res.n_changed) == differing(bed.colour, res.colours));
    };
    auto check_rejected = [&](const LiftResult& res, const char* why) {
        CHECK(res.status == LiftStatus::rejected);
        CHECK_FALSE(res.applied());
        CHECK(res.n_changed == 0);
        CHECK_THAT(res.message, Catch::Contains("rejected") && Catch::Contains(why));
    };

    SECTION("a non-finite target") {
        Eigen::VectorXd target = current;
        target[4] = std::numeric_limits<double>::quiet_NaN();
        const LiftResult res = lift_colours(target, bed.z, bed.colour, kGrid, rng);
        check_rejected(res, "not finite at node 4");
        CHECK(res.colours == bed.colour);
        CHECK(res.achieved_icdf == current);
    }
    SECTION("a non-finite height") {
        auto z = bed.z;
        z[17] = std::numeric_limits<double>::infinity();
        check_rejected(lift_colours(current, z, bed.colour, kGrid, rng), "particle 17");
    }
    SECTION("all heights equal") {
        const std::vector<double> flat(bed.z.size(), 3.0);
        check_rejected(lift_colours(current, flat, bed.colour, kGrid, rng), "same height");
    }
    SECTION("no light particle") {
        const Labels heavy(bed.z.size(), kHeavy);
        check_rejected(lift_colours(current, bed.z, heavy, kGrid, rng), "no light particles");
    }
    SECTION("above the bed: clipped to the top, and the top interval too small") {
        const Eigen::VectorXd above = current.array() + 100.0;
        const LiftResult res = lift_colours(above, bed.z, bed.colour, kGrid, rng);
        CHECK(res.status == LiftStatus::adjusted);
        CHECK(res.repair.n_clipped == 19);
        CHECK(res.target == Eigen::VectorXd::Constant(19, z_max));
        // 18 empty intervals [z_max, z_max), and only the top particle lies in [z_max, inf).
        CHECK(res.n_short_intervals == 19);
        CHECK_THAT(res.message, Catch::Contains("clipped") && Catch::Contains("fewer particles"));
        check_invariants(res);
    }
    SECTION("not monotone: repaired first") {
        Eigen::VectorXd zigzag = current;
        std::swap(zigzag[5], zigzag[12]);
        const LiftResult res = lift_colours(zigzag, bed.z, bed.colour, kGrid, rng);
        CHECK(res.status == LiftStatus::adjusted);
        CHECK(res.repair.non_monotone);
        CHECK((res.target.tail(18) - res.target.head(18)).minCoeff() >= 0.0);
        check_invariants(res);
    }
    SECTION("a target squeezed into a band with too few particles") {
        // All 19 cuts within 0.01 d_p (~0.4 particles of 2000 per d_p... i.e. ~0 particles
        // between cuts): the light counts cannot be met, the excess moves to the neighbours.
        const Eigen::VectorXd band = Eigen::VectorXd::LinSpaced(19, 25.0, 25.01);
        const LiftResult res = lift_colours(band, bed.z, bed.colour, kGrid, rng);
        CHECK(res.status == LiftStatus::adjusted);
        CHECK(res.n_short_intervals > 10);
        CHECK_THAT(res.message, Catch::Contains("fewer particles"));
        check_invariants(res);
        // Half the lights below the band and half above is still achievable and achieved:
        // the median node sits in the band to within the bed's light spacing (~0.1 d_p).
        CHECK(res.achieved_icdf[9] == Approx(25.005).margin(0.5));
    }
}

TEST_CASE("colour lifting cost grows like N log m", "[.benchmark][coarse]") {
    // Not in the default tier (timing). Median CPU time (std::clock: a shared machine's load
    // does not count) of 11 lifts for N = 1e4 and 1e5 on a demixing target, for each relabelling.
    // O(N log m) predicts a ratio of 10 (11 measured: 1e5 particles no longer fit in L2), the
    // sorts of at_nodes O(N log(N/m)) a little more, O(N^2) 100: < 30 passes.
    auto seconds_per_lift = [](std::size_t n, Relabel relabel) {
        efdem::RandomStream rng(35, n, "bench");
        const Bed bed = random_bed(rng, n, 0.5);
        const Eigen::VectorXd target =
            quantiles(light_heights(bed, demixed_labels(rng, bed, 0.3)), kGrid);
        std::vector<double> t;
        for (int r = 0; r < 11; ++r) {
            const std::clock_t start = std::clock();
            const LiftResult res = lift_colours(target, bed.z, bed.colour, kGrid, rng, {}, relabel);
            t.push_back(static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC);
            REQUIRE(res.status == LiftStatus::ok);
        }
        std::nth_element(t.begin(), t.begin() + 5, t.end());
        return t[5];
    };
    for (const Relabel relabel : {Relabel::at_nodes, Relabel::random}) {
        const double small = seconds_per_lift(10000, relabel);
        const double large = seconds_per_lift(100000, relabel);
        WARN("lift_colours CPU time (" << (relabel == Relabel::random ? "random" : "at_nodes")
                                       << "): " << small * 1e3 << " ms for N = 1e4, " << large * 1e3
                                       << " ms for N = 1e5; 1024 realizations of "
                                       << "1e5: " << 1024 * large << " s");
        CHECK(large / small < 30.0);
    }
}
