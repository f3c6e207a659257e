#include "coarse/demixing/node_pins.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "coarse/demixing/quantiles.hpp"
#include "core/contracts.hpp"

namespace efdem::coarse {

namespace {

using Count = std::int64_t;

/// Where a rank may be pinned in its interval: positions [low, high] of order[k].
struct Room {
    std::size_t interval = 0;
    Count offset = 0, low = 0, high = 0;
};

class Pinner {
  public:
    Pinner(const LiftPlan& plan, const IntervalOrder& order, std::span<const double> heights,
           std::span<const std::uint8_t> colours, std::span<const std::uint8_t> prefer, int reach)
        : plan_(plan),
          order_(order),
          heights_(heights),
          colours_(colours),
          prefer_(prefer),
          reach_(reach),
          last_offset_(order.size(), -1),
          last_position_(order.size(), 0) {}

    /// Pins the defining ranks of one node (`upper` < 0: the node sits on rank `lower`).
    void pin_node(Count lower, Count upper, double fraction, double target) {
        const std::optional<RankPin> fixed = pinned(lower);
        if (fixed && (upper < 0 || pinned(upper))) return;
        const Room room_u = room(lower);
        // With `prefer`, first among the preferred particles (and the observed ones), then, if
        // that leaves no pair, among all.
        for (const bool filtered : {true, false}) {
            if (filtered && prefer_.empty()) continue;
            const std::vector<Count> us =
                fixed ? std::vector<Count>{static_cast<Count>(fixed->position)}
                      : candidates(room_u, target, filtered);
            if (choose(us, room_u, upper, fraction, target, filtered, fixed.has_value())) return;
        }
        EFDEM_ASSERT(false && "the room always holds a pair");
    }

    std::vector<RankPin> pins() && { return std::move(pins_); }

  private:
    std::optional<RankPin> pinned(Count rank) const {
        for (auto it = pins_.rbegin(); it != pins_.rend() && it->rank >= rank; ++it)
            if (it->rank == rank) return *it;
        return std::nullopt;
    }

    Room room(Count rank) const {
        const auto& below = plan_.below;
        Room r;
        r.interval = static_cast<std::size_t>(std::upper_bound(below.begin(), below.end(), rank) -
                                              below.begin() - 1);
        const std::size_t k = r.interval;
        r.offset = rank - below[k];
        const auto population = static_cast<Count>(order_[k].size());
        const Count n_k = below[k + 1] - below[k];
        r.low = last_offset_[k] < 0
                    ? r.offset
                    : static_cast<Count>(last_position_[k]) + (r.offset - last_offset_[k]);
        r.high = population - n_k + r.offset;
        EFDEM_ASSERT(r.low <= r.high);
        return r;
    }

    double height(std::size_t k, Count position) const {
        return heights_[order_[k][static_cast<std::size_t>(position)]];
    }
    bool observed(std::size_t k, Count position) const {
        return colours_[order_[k][static_cast<std::size_t>(position)]] == kLight;
    }
    bool allowed(std::size_t k, Count position, bool filtered) const {
        return !filtered || observed(k, position) ||
               prefer_[order_[k][static_cast<std::size_t>(position)]] != 0;
    }

    /// The positions of the room nearest `target` (reach on each side) and its observed
    /// particles nearest the target from below and from above.
    std::vector<Count> candidates(const Room& r, double target, bool filtered) const {
        const std::size_t k = r.interval;
        const auto& bucket = order_[k];
        const auto first_above = static_cast<Count>(
            std::partition_point(bucket.begin(), bucket.end(),
                                 [&](std::size_t j) { return heights_[j] < target; }) -
            bucket.begin());
        std::vector<Count> out;
        auto add = [&](Count p) {
            if (p >= r.low && p <= r.high && allowed(k, p, filtered)) out.push_back(p);
        };
        for (Count p = first_above - reach_; p < first_above + reach_; ++p)
            add(std::clamp(p, r.low, r.high));
        for (Count p = std::min(first_above - 1, r.high); p >= r.low; --p)
            if (observed(k, p)) {
                add(p);
                break;
            }
        for (Count p = std::max(first_above, r.low); p <= r.high; ++p)
            if (observed(k, p)) {
                add(p);
                break;
            }
        std::sort(out.begin(), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
        return out;
    }

    /// The best pair (u from `us`, v for rank `upper`), pinned; false when no pair exists.
    bool choose(const std::vector<Count>& us, const Room& room_u, Count upper, double fraction,
                double target, bool filtered, bool u_fixed) {
        constexpr double kTie = 1e-9;  // d_p: nodes this close count as equally good
        struct Best {
            double error = std::numeric_limits<double>::infinity();
            int switches = 0;
            Count u = -1, v = -1;
        } best;
        std::optional<Room> room_v;
        if (upper >= 0) room_v = room(upper);
        // In another interval the upper rank's candidates do not depend on u: found once.
        const bool same_interval = room_v && room_v->interval == room_u.interval;
        const std::vector<Count> vs_apart =
            room_v && !same_interval ? candidates(*room_v, target, filtered) : std::vector<Count>{};
        auto consider = [&](Count u, Count v, double node) {
            const double error = std::abs(node - target);
            const int switches = (u_fixed || observed(room_u.interval, u) ? 0 : 1) +
                                 (v < 0 || observed(room_v->interval, v) ? 0 : 1);
            if (error < best.error - kTie ||
                (error <= best.error + kTie && switches < best.switches))
                best = {std::min(error, best.error), switches, u, v};
        };
        for (const Count u : us) {
            const double zu = height(room_u.interval, u);
            if (!room_v) {
                consider(u, -1, zu);
                continue;
            }
            std::vector<Count> vs = vs_apart;
            if (same_interval) {
                Room rv = *room_v;
                rv.low = std::max(rv.low, u + 1);
                if (rv.low > rv.high) continue;
                vs = candidates(rv, target, filtered);
                if (allowed(rv.interval, u + 1, filtered))
                    vs.push_back(u + 1);  // the tightest pair is always within the room
            }
            for (const Count v : vs)
                consider(u, v, zu + fraction * (height(room_v->interval, v) - zu));
        }
        if (best.u < 0) return false;
        if (!u_fixed) add_pin(room_u, best.u);
        if (room_v) add_pin(*room_v, best.v);
        return true;
    }

    void add_pin(const Room& r, Count position) {
        pins_.push_back({plan_.below[r.interval] + r.offset, r.interval, r.offset,
                         static_cast<std::size_t>(position)});
        last_offset_[r.interval] = r.offset;
        last_position_[r.interval] = static_cast<std::size_t>(position);
    }

    const LiftPlan& plan_;
    const IntervalOrder& order_;
    std::span<const double> heights_;
    std::span<const std::uint8_t> colours_;
    std::span<const std::uint8_t> prefer_;
    int reach_;
    std::vector<Count> last_offset_;
    std::vector<std::size_t> last_position_;
    std::vector<RankPin> pins_;
};

}  // namespace

IntervalOrder order_intervals(const LiftPlan& plan, std::span<const double> heights) {
    EFDEM_EXPECTS(plan.interval.size() == heights.size());
    IntervalOrder order = particles_by_interval(plan);
    for (auto& bucket : order)
        std::sort(bucket.begin(), bucket.end(), [&](std::size_t a, std::size_t b) {
            return heights[a] < heights[b] || (heights[a] == heights[b] && a < b);
        });
    return order;
}

std::vector<RankPin> pin_node_ranks(const LiftPlan& plan, const IntervalOrder& order,
                                    std::span<const double> heights,
                                    std::span<const std::uint8_t> colours,
                                    const ProbabilityGrid& grid,
                                    std::span<const std::uint8_t> prefer, int reach) {
    EFDEM_EXPECTS(plan.error.empty() && order.size() == plan.population.size());
    EFDEM_EXPECTS(colours.size() == heights.size() &&
                  (prefer.empty() || prefer.size() == heights.size()) && reach >= 1);
    Pinner pinner(plan, order, heights, colours, prefer, reach);
    for (int i = 0; i < grid.size(); ++i) {
        const NodeRank r = node_rank(grid, i, plan.n_observed);
        pinner.pin_node(r.lower, r.fraction != 0.0 ? r.lower + 1 : -1, r.fraction, plan.target[i]);
    }
    return std::move(pinner).pins();
}

}  // namespace efdem::coarse
