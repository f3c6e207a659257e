#include "core/bounds.hpp"

#include <fmt/format.h>
#include <cmath>

namespace efdem {

std::string Bounds::describe() const {
    const bool has_lo = std::isfinite(lo);
    const bool has_hi = std::isfinite(hi);
    if (!has_lo && !has_hi) return "";
    if (has_lo && !has_hi) return fmt::format("{} {}", lo_open ? ">" : ">=", lo);
    if (!has_lo && has_hi) return fmt::format("{} {}", hi_open ? "<" : "<=", hi);
    return "in " + interval();
}

std::string Bounds::interval() const {
    return fmt::format("{}{}, {}{}", lo_open ? "(" : "[", lo, hi, hi_open ? ")" : "]");
}

}  // namespace efdem
