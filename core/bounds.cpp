#include "core/bounds.hpp"

#include <fmt/format.h>
#include <cmath>

namespace efdem {

namespace {
/// A bound as a user writes it: 15 significant digits, so that a bound computed as 1e-6 x 2e5
/// reads 0.2, not 0.19999999999999998.
std::string shown(double v) {
    return fmt::format("{:.15g}", v);
}
}  // namespace

std::string Bounds::describe() const {
    const bool has_lo = std::isfinite(lo);
    const bool has_hi = std::isfinite(hi);
    if (!has_lo && !has_hi) return "";
    if (has_lo && !has_hi) return fmt::format("{} {}", lo_open ? ">" : ">=", shown(lo));
    if (!has_lo && has_hi) return fmt::format("{} {}", hi_open ? "<" : "<=", shown(hi));
    return "in " + interval();
}

std::string Bounds::interval() const {
    return fmt::format("{}{}, {}{}", lo_open ? "(" : "[", shown(lo), shown(hi),
                       hi_open ? ")" : "]");
}

}  // namespace efdem
