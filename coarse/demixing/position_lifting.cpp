#include "coarse/demixing/position_lifting.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "coarse/demixing/rank_windows.hpp"
#include "core/contracts.hpp"
#include "core/periodic.hpp"

namespace efdem::coarse {

namespace {

using Count = std::int64_t;

/// One exchange: a large particle from `large_interval` against a group of `group` small ones
/// drawn from intervals small_lo..small_hi.
struct Exchange {
    std::size_t large_interval = 0;
    std::size_t small_lo = 0, small_hi = 0;
    Count group = 0;
};

/// Entry k of `list` repeated count_k times, k ascending (count_k = max(0, sign * gain_k)).
std::vector<std::size_t> repeated_intervals(const LiftPlan& plan, int sign) {
    std::vector<std::size_t> list;
    for (std::size_t k = 0; k < plan.population.size(); ++k)
        for (Count c = 0; c < sign * plan.gain(k); ++c) list.push_back(k);
    return list;
}

/// Size of the t-th of a run of groups of rho small particles on average: round(rho (t + 1))
/// - round(rho t), so that T groups hold round(rho T) in all.
Count group_size(double rho, std::size_t t) {
    return std::llround(rho * static_cast<double>(t + 1)) -
           std::llround(rho * static_cast<double>(t));
}

/// The exchanges of step 2a (position_lifting.hpp, the small species observed), lowest first.
std::vector<Exchange> plan_exchanges(const LiftPlan& plan, double rho) {
    const std::vector<std::size_t> losing = repeated_intervals(plan, -1);
    const std::vector<std::size_t> gaining = repeated_intervals(plan, +1);
    EFDEM_ASSERT(losing.size() == gaining.size());
    const auto moves = static_cast<Count>(losing.size());
    std::vector<Exchange> out;
    const auto n = static_cast<Count>(std::llround(static_cast<double>(moves) / rho));
    for (Count t = 0; t < n; ++t) {
        const Count first = t * moves / n, last = (t + 1) * moves / n;
        const auto middle = static_cast<std::size_t>((2 * t + 1) * moves / (2 * n));
        out.push_back({gaining[middle], losing[static_cast<std::size_t>(first)],
                       losing[static_cast<std::size_t>(last - 1)], last - first});
    }
    return out;
}

/// One exchange to make: the large particle, its group of small ones, where the large one goes.
struct Move {
    std::size_t large = 0;
    std::vector<std::size_t> group;
    Vec3 destination{};
};

class Exchanger {
  public:
    Exchanger(const LiftPlan& plan, std::span<const Vec3> x, std::span<const std::uint8_t> colours,
              std::uint8_t small_colour, const TwoSizes& sizes, RandomStream& rng)
        : plan_(plan),
          x_(x),
          colours_(colours),
          small_colour_(small_colour),
          sizes_(sizes),
          rng_(rng),
          chosen_(x.size(), 0),
          by_interval_(particles_by_interval(plan)),
          quota_(plan.population.size(), 0) {
        if (small_colour == kLight)  // the small ones are observed: each interval sends its loss
            for (std::size_t k = 0; k < quota_.size(); ++k)
                quota_[k] = std::max<Count>(0, -plan.gain(k));
    }

    /// The particles of one exchange: {large, group...}; empty if no large particle is left.
    std::vector<std::size_t> pick(const Exchange& e) {
        const std::uint8_t large_colour = small_colour_ ^ 1u;
        const std::size_t large = pick_random(e.large_interval, large_colour);
        if (large == kNone) return {};
        std::vector<std::size_t> out{large};
        const bool quotas = small_colour_ == kLight;
        bool widened = false;
        const std::vector<std::size_t> near =
            candidates(e.small_lo, e.small_hi, e.group, quotas, widened);
        if (near.empty()) return out;
        // A random seed among the candidates of the group's lowest interval (any candidate if
        // that one has none).
        std::vector<std::size_t> in_lowest;
        for (std::size_t j : near)
            if (plan_.interval[j] == e.small_lo) in_lowest.push_back(j);
        const std::vector<std::size_t>& seeds = in_lowest.empty() ? near : in_lowest;
        take_nearest(near, x_[seeds[rng_.below(seeds.size())]], e.group, quotas, out);
        return out;
    }

    /**
     * `count` unchosen small particles about height z, from the plan's interval that holds z
     * (widened by one interval each side while too few, then `far` is set): a random seed among
     * those, then the nearest to the point at the seed's x, y and height z. Drawn from the
     * interval the large particle goes to, the group keeps that interval's solid volume.
     */
    std::vector<std::size_t> group_at_height(double z, Count count, bool& far) {
        const std::size_t k =
            cuts_at_or_below(std::span<const double>(plan_.target.data(), plan_.target.size()), z);
        const std::vector<std::size_t> near = candidates(k, k, count, false, far);
        std::vector<std::size_t> group;
        if (near.empty()) return group;
        const Vec3 seed = x_[near[rng_.below(near.size())]];
        take_nearest(near, {seed.x, seed.y, z}, count, false, group);
        return group;
    }

    /// The group's centroid, unwrapped around its first member.
    Vec3 centroid(std::span<const std::size_t> group) const {
        Vec3 sum{};
        for (std::size_t j : group) sum += separation(x_[j], x_[group[0]]);
        return x_[group[0]] + sum * (1.0 / static_cast<double>(group.size()));
    }
    Vec3 offset(std::size_t j, const Vec3& from) const { return separation(x_[j], from); }

  private:
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);

    Vec3 separation(const Vec3& a, const Vec3& b) const {
        return minimum_image_xy(a - b, sizes_.lx, sizes_.ly);
    }

    /// A random unchosen particle of `colour` in interval k, or in the nearest interval that has
    /// one (below first on a tie).
    std::size_t pick_random(std::size_t k, std::uint8_t colour) {
        const std::size_t n = by_interval_.size();
        for (std::size_t r = 0; r < n; ++r)
            for (const std::size_t q : {k - r, k + r}) {
                if (q >= n) continue;  // k - r wrapped below 0, or past the top
                std::vector<std::size_t> c;
                for (std::size_t j : by_interval_[q])
                    if (!chosen_[j] && colours_[j] == colour) c.push_back(j);
                if (c.empty()) continue;
                const std::size_t j = c[rng_.below(c.size())];
                chosen_[j] = 1;
                return j;
            }
        return kNone;
    }

    /// The unchosen small particles of intervals lo..hi (with `quotas`, of intervals whose quota
    /// is not spent), the range widened by one interval each side while fewer than `count`
    /// (then `widened` is set) until it spans every interval.
    std::vector<std::size_t> candidates(std::size_t lo, std::size_t hi, Count count, bool quotas,
                                        bool& widened) const {
        widened = false;
        for (;; widened = true) {
            std::vector<std::size_t> out;
            for (std::size_t k = lo; k <= hi; ++k)
                for (std::size_t j : by_interval_[k])
                    if (!chosen_[j] && colours_[j] == small_colour_ && (!quotas || quota_[k] > 0))
                        out.push_back(j);
            if (static_cast<Count>(out.size()) >= count || (lo == 0 && hi + 1 == quota_.size()))
                return out;
            lo = lo > 0 ? lo - 1 : lo;
            hi = hi + 1 < quota_.size() ? hi + 1 : hi;
        }
    }

    /// Up to `count` of `candidates`, nearest to `centre` first (periodic in x, y), taking each
    /// interval's quota with `quotas`; marked chosen and appended to `out`.
    void take_nearest(const std::vector<std::size_t>& candidates, const Vec3& centre, Count count,
                      bool quotas, std::vector<std::size_t>& out) {
        std::vector<std::pair<double, std::size_t>> by_distance;
        by_distance.reserve(candidates.size());
        for (std::size_t j : candidates)
            by_distance.emplace_back(norm2(separation(x_[j], centre)), j);
        std::sort(by_distance.begin(), by_distance.end());
        Count taken = 0;
        for (const auto& [d2, j] : by_distance) {
            if (taken == count) break;
            const std::size_t k = plan_.interval[j];
            if (quotas && quota_[k] == 0) continue;
            if (quotas) --quota_[k];
            chosen_[j] = 1;
            out.push_back(j);
            ++taken;
        }
    }

    const LiftPlan& plan_;
    std::span<const Vec3> x_;
    std::span<const std::uint8_t> colours_;
    std::uint8_t small_colour_;
    const TwoSizes& sizes_;
    RandomStream& rng_;
    std::vector<std::uint8_t> chosen_;
    std::vector<std::vector<std::size_t>> by_interval_;
    std::vector<Count> quota_;
};

}  // namespace

PositionLiftResult lift_positions(const Eigen::VectorXd& target_icdf,
                                  std::span<const Vec3> positions, std::span<const Vec3> velocities,
                                  std::span<const std::uint8_t> colours, const TwoSizes& sizes,
                                  const ProbabilityGrid& grid, RandomStream& rng) {
    EFDEM_EXPECTS(positions.size() == colours.size() && velocities.size() == colours.size());
    EFDEM_EXPECTS(sizes.observed_diameter > 0 && sizes.other_diameter > 0);
    const double d_large = std::max(sizes.observed_diameter, sizes.other_diameter);
    const double d_small = std::min(sizes.observed_diameter, sizes.other_diameter);
    EFDEM_EXPECTS(d_large <= 4 * d_small);
    EFDEM_EXPECTS(sizes.lx > 0 && sizes.ly > 0);

    PositionLiftResult result;
    result.positions.assign(positions.begin(), positions.end());
    result.velocities.assign(velocities.begin(), velocities.end());
    result.moved.assign(positions.size(), 0);
    std::vector<double> heights(positions.size());
    for (std::size_t j = 0; j < positions.size(); ++j) heights[j] = positions[j].z;
    const LiftPlan plan = plan_lift(target_icdf, heights, colours, grid);
    result.target = plan.error.empty() ? plan.target : target_icdf;
    if (!plan.error.empty()) {
        result.message = "lifting rejected, no particle moved: " + plan.error;
        return result;
    }
    result.repair = plan.repair;
    const double rho = std::pow(d_large / d_small, 3);
    result.volume_ratio = rho;
    const bool observed_is_small = sizes.observed_diameter <= sizes.other_diameter;
    const std::uint8_t small_colour = observed_is_small ? kLight : kHeavy;
    result.n_short_intervals = observed_is_small ? plan.n_short_intervals : 0;
    const double m_small = observed_is_small ? sizes.observed_mass : sizes.other_mass;
    const double m_large = observed_is_small ? sizes.other_mass : sizes.observed_mass;
    const double r_large = d_large / 2, r_small = d_small / 2;

    Exchanger exchanger(plan, positions, colours, small_colour, sizes, rng);
    std::size_t dropped = 0, far = 0;
    std::vector<Move> moves;
    if (observed_is_small) {
        for (const Exchange& e : plan_exchanges(plan, rho)) {
            const std::vector<std::size_t> picked = exchanger.pick(e);
            if (picked.size() < 2) {
                ++dropped;
                continue;
            }
            Move mv{picked[0], {picked.begin() + 1, picked.end()}, {}};
            mv.destination = exchanger.centroid(mv.group);
            moves.push_back(std::move(mv));
        }
    } else {
        // Step 2b: rank by rank. The observed particles sorted by height; those outside their
        // rank's window leave, lowest first, for the free ranks, lowest first.
        std::vector<std::size_t> observed;
        double z_low = r_large, z_high = heights[0];
        for (std::size_t j = 0; j < heights.size(); ++j) {
            z_high = std::max(z_high, heights[j]);
            if (colours[j] != kLight) continue;
            observed.push_back(j);
            z_low = std::min(z_low, heights[j]);
        }
        std::sort(observed.begin(), observed.end(),
                  [&](std::size_t a, std::size_t b) { return heights[a] < heights[b]; });
        std::vector<double> sorted(observed.size());
        for (std::size_t q = 0; q < observed.size(); ++q) sorted[q] = heights[observed[q]];
        const RankWindows windows =
            rank_windows(plan.target, grid, static_cast<Count>(observed.size()), sizes.resolution,
                         z_low, z_high);
        const std::vector<Count> kept = ranks_kept(sorted, windows);
        std::vector<std::uint8_t> taken(observed.size(), 0);
        std::vector<std::size_t> leaving;
        for (std::size_t q = 0; q < observed.size(); ++q) {
            if (kept[q] < 0)
                leaving.push_back(observed[q]);
            else
                taken[static_cast<std::size_t>(kept[q])] = 1;
        }
        std::vector<std::size_t> free_ranks;
        for (std::size_t k = 0; k < taken.size(); ++k)
            if (!taken[k]) free_ranks.push_back(k);
        EFDEM_ASSERT(free_ranks.size() == leaving.size());
        for (std::size_t t = 0; t < leaving.size(); ++t) {
            const double z = windows.desired[free_ranks[t]];
            bool widened = false;
            Move mv{leaving[t], exchanger.group_at_height(z, group_size(rho, t), widened), {}};
            far += widened;
            if (mv.group.empty()) {
                ++dropped;
                continue;
            }
            const Vec3 c = exchanger.centroid(mv.group);
            mv.destination = {c.x, c.y, z};
            moves.push_back(std::move(mv));
        }
    }
    for (const Move& mv : moves) {
        const std::size_t large = mv.large;
        const std::span<const std::size_t> group(mv.group);
        const Vec3 c = exchanger.centroid(group);
        double rms = 0;
        Vec3 mean_v{};
        for (std::size_t j : group) {
            rms += norm2(exchanger.offset(j, c));
            mean_v += velocities[j];
        }
        rms = std::sqrt(rms / static_cast<double>(group.size()));
        mean_v *= 1.0 / static_cast<double>(group.size());
        const double fill = std::sqrt(3.0 / 5.0) * (r_large - r_small);
        const double scale = rms > fill ? fill / rms : 1.0;
        const Vec3 home = positions[large];
        for (std::size_t j : group) {
            result.positions[j] = home + exchanger.offset(j, c) * scale;
            result.velocities[j] = velocities[large] + (velocities[j] - mean_v);
            result.moved[j] = 1;
        }
        result.positions[large] = mv.destination;
        result.velocities[large] = mean_v;
        result.moved[large] = 1;
        ++result.n_exchanges;
        result.n_moved += 1 + group.size();
    }
    // Masses matched: the large particle carries the group's momentum; otherwise (other
    // densities or group sizes off the ratio) a change is left and reported.
    Vec3 dp{};
    double dke = 0;
    for (std::size_t j = 0; j < positions.size(); ++j) {
        const double m = (colours[j] == small_colour) ? m_small : m_large;
        result.positions[j] = wrap_xy(result.positions[j], sizes.lx, sizes.ly);
        dp += (result.velocities[j] - velocities[j]) * m;
        dke += 0.5 * m * (norm2(result.velocities[j]) - norm2(velocities[j]));
    }
    result.momentum_change = std::sqrt(norm2(dp));
    result.kinetic_energy_change = dke;

    // The solid volume of each interval of the plan, before and after [small volumes].
    const std::span<const double> cuts(plan.target.data(), plan.target.size());
    std::vector<double> dv(plan.population.size(), 0.0);
    for (std::size_t j = 0; j < positions.size(); ++j) {
        if (!result.moved[j]) continue;
        const double v = colours[j] == small_colour ? 1.0 : rho;
        dv[plan.interval[j]] -= v;
        dv[cuts_at_or_below(cuts, result.positions[j].z)] += v;
    }
    for (double d : dv) result.max_volume_change = std::max(result.max_volume_change, std::abs(d));

    for (std::size_t j = 0; j < positions.size(); ++j) heights[j] = result.positions[j].z;
    result.achieved_icdf = observed_icdf(heights, colours, grid);
    result.max_deviation = (result.achieved_icdf - result.target).cwiseAbs().maxCoeff();
    const bool short_counts = observed_is_small && plan.below != plan.wanted;
    result.status = result.repair.changed() || short_counts || dropped > 0 ? LiftStatus::adjusted
                                                                           : LiftStatus::ok;
    result.message = result.repair.message;
    auto add = [&](const std::string& what) {
        result.message += (result.message.empty() ? "" : "; ") + what;
    };
    if (short_counts) add(plan.shortage("observed", ""));
    if (dropped > 0)
        add(fmt::format("{} exchange(s) found no {} particle left to move", dropped,
                        observed_is_small ? "large" : "small"));
    if (far > 0)
        add(
            fmt::format("{} exchange(s) took small particles from beyond the interval of the "
                        "large one's new height",
                        far));
    EFDEM_ENSURES(result.n_moved == static_cast<std::size_t>(
                                        std::count(result.moved.begin(), result.moved.end(), 1)));
    return result;
}

}  // namespace efdem::coarse
