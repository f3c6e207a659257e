// The colour lift offline on saved states: every realization lifted to the ensemble's own
// coarse state (the lift at a steady state, where the target is the current mean), and how far
// the lifted ensemble's mean then lies from that target, node by node. bench/lift_offline.py
// writes the states from a checkpoint and runs this for each rule.
//
//   efdem_lift_offline STATE N_PER_REALIZATION icdf|ranks matched|random
//
// STATE: one line per particle, "x y z species" (species 0 = light), realization after
// realization. Output: one line "node_miss" with the 19 nodes' miss of the mean [d_p] (in the
// coordinate lifted: heights of the ICDF, or the rank coordinate's reference heights), then
// "rms_mean_miss", "rms_member_miss" and "switched_per_realization".
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "coarse/demixing/colour_lifting.hpp"
#include "coarse/demixing/lift_plan.hpp"
#include "coarse/demixing/quantiles.hpp"
#include "coarse/demixing/rank_observable.hpp"
#include "coarse/demixing/whole_bed_profile.hpp"
#include "coarse/equation_free/ensemble_statistics.hpp"
#include "core/rng.hpp"

using namespace efdem::coarse;

namespace {

int usage() {
    std::fprintf(stderr,
                 "usage: efdem_lift_offline STATE N_PER_REALIZATION icdf|ranks matched|random\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 5) return usage();
    const std::string observable = argv[3], rule = argv[4];
    const long n = std::atol(argv[2]);
    if (n < 2 || (observable != "icdf" && observable != "ranks") ||
        (rule != "matched" && rule != "random"))
        return usage();
    std::ifstream in(argv[1]);
    if (!in) {
        std::fprintf(stderr, "efdem_lift_offline: cannot read %s\n", argv[1]);
        return 2;
    }
    std::vector<double> all_z;
    std::vector<int> all_species;
    double x, y, z;
    int s;
    while (in >> x >> y >> z >> s) {
        all_z.push_back(z);
        all_species.push_back(s);
    }
    const auto size = static_cast<long>(all_z.size());
    if (size == 0 || size % n != 0) {
        std::fprintf(stderr, "efdem_lift_offline: %ld particles are not realizations of %ld\n",
                     size, n);
        return 2;
    }
    const long realizations = size / n;
    const ProbabilityGrid grid;
    const auto m = static_cast<Eigen::Index>(grid.size());
    std::vector<std::vector<double>> heights(static_cast<std::size_t>(realizations));
    std::vector<std::vector<std::uint8_t>> colours(static_cast<std::size_t>(realizations));
    Eigen::MatrixXd icdf(realizations, m), profiles(realizations, kWholeBedNodes);
    for (long r = 0; r < realizations; ++r) {
        auto& h = heights[static_cast<std::size_t>(r)];
        auto& c = colours[static_cast<std::size_t>(r)];
        h.assign(all_z.begin() + r * n, all_z.begin() + (r + 1) * n);
        c.resize(static_cast<std::size_t>(n));
        for (long j = 0; j < n; ++j)
            c[static_cast<std::size_t>(j)] =
                all_species[static_cast<std::size_t>(r * n + j)] == 0 ? kLight : kHeavy;
        icdf.row(r) = observed_icdf(h, c, grid).transpose();
        profiles.row(r) = profile_of_heights(h).transpose();
    }
    // The coarse state X and each member's target: the ICDF's mean lifted as it is; in rank
    // coordinates X is the members' mean rank state and each member's target its own heights.
    RankObservable ranks(grid);
    const bool by_ranks = observable == "ranks";
    const Eigen::VectorXd target =
        by_ranks ? ranks.restrict_ensemble(icdf, profiles) : ensemble_mean(icdf);
    const Relabel relabel = rule == "matched" ? Relabel::at_nodes : Relabel::random;
    Eigen::MatrixXd lifted(realizations, m);
    double switched = 0.0;
    for (long r = 0; r < realizations; ++r) {
        const auto k = static_cast<std::size_t>(r);
        const Eigen::VectorXd profile = profiles.row(r).transpose();
        const Eigen::VectorXd member_target =
            by_ranks ? ranks.lift_target(target, profile) : target;
        efdem::RandomStream rng(42, static_cast<std::uint64_t>(r), "lift");
        const LiftResult res =
            lift_colours(member_target, heights[k], colours[k], grid, rng, {}, relabel);
        lifted.row(r) = res.achieved_icdf.transpose();
        switched += static_cast<double>(res.n_changed);
    }
    const Eigen::MatrixXd in_coordinate =
        by_ranks ? ranks.restrict_members(lifted, profiles) : lifted;
    const Eigen::VectorXd miss = ensemble_mean(in_coordinate) - target;
    double member_sq = 0.0;
    for (long r = 0; r < realizations; ++r)
        member_sq += (in_coordinate.row(r).transpose() - target).squaredNorm();
    std::printf("node_miss");
    for (Eigen::Index i = 0; i < m; ++i) std::printf(" %+.4f", miss[i]);
    std::printf("\nrms_mean_miss %.4f\nrms_member_miss %.4f\nswitched_per_realization %.1f\n",
                std::sqrt(miss.squaredNorm() / static_cast<double>(m)),
                std::sqrt(member_sq / static_cast<double>(m * realizations)),
                switched / static_cast<double>(realizations));
    return 0;
}
