#include "coarse/demixing/monotone_repair.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/contracts.hpp"

namespace efdem::coarse {

void isotonic_regression(Eigen::Ref<Eigen::VectorXd> x) {
    EFDEM_EXPECTS(x.allFinite());
    struct Block {
        double mean;
        Eigen::Index count;
    };
    std::vector<Block> blocks;
    blocks.reserve(static_cast<std::size_t>(x.size()));
    for (Eigen::Index i = 0; i < x.size(); ++i) {
        blocks.push_back({x[i], 1});
        while (blocks.size() > 1 && blocks[blocks.size() - 2].mean > blocks.back().mean) {
            const Block top = blocks.back();
            blocks.pop_back();
            Block& below = blocks.back();
            const auto total = below.count + top.count;
            below.mean = (below.mean * static_cast<double>(below.count) +
                          top.mean * static_cast<double>(top.count)) /
                         static_cast<double>(total);
            below.count = total;
        }
    }
    Eigen::Index i = 0;
    for (const Block& b : blocks) {
        // A block of one keeps its original value (no rounding through mean * 1 / 1).
        if (b.count > 1) x.segment(i, b.count).setConstant(b.mean);
        i += b.count;
    }
}

RepairReport repair_monotone(Eigen::VectorXd& x, double z_min, double z_max) {
    EFDEM_EXPECTS(std::isfinite(z_min) && std::isfinite(z_max) && z_min <= z_max);
    RepairReport report;
    for (Eigen::Index i = 0; i < x.size(); ++i) {
        if (!std::isfinite(x[i])) {
            report.feasible = false;
            report.message = fmt::format(
                "ICDF target is not finite at node {} (value {}): rejected, nothing repaired", i,
                x[i]);
            return report;
        }
    }
    const Eigen::VectorXd original = x;
    int n_decreasing = 0;
    for (Eigen::Index i = 1; i < x.size(); ++i)
        if (x[i] < x[i - 1]) ++n_decreasing;
    report.non_monotone = n_decreasing > 0;
    if (report.non_monotone) isotonic_regression(x);
    for (Eigen::Index i = 0; i < x.size(); ++i) {
        if (x[i] < z_min || x[i] > z_max) {
            x[i] = std::clamp(x[i], z_min, z_max);
            ++report.n_clipped;
        }
    }
    report.max_adjustment = x.size() == 0 ? 0.0 : (x - original).cwiseAbs().maxCoeff();
    std::vector<std::string> parts;
    if (report.non_monotone)
        parts.push_back(
            fmt::format("target decreased at {} node pair(s); isotonic regression "
                        "applied",
                        n_decreasing));
    if (report.n_clipped > 0)
        parts.push_back(fmt::format("{} node(s) clipped into the feasible range [{:.6g}, {:.6g}]",
                                    report.n_clipped, z_min, z_max));
    if (!parts.empty())
        report.message =
            fmt::format("{}; largest change {:.3g}", fmt::join(parts, "; "), report.max_adjustment);
    return report;
}

}  // namespace efdem::coarse
