#pragma once
/// \file
/// Bounds: an allowed numeric interval that can describe itself in an error message.

#include <limits>
#include <string>

namespace efdem {

/**
 * \brief A numeric interval [lo, hi] with optionally open ends, used to validate scene values.
 *
 * \code
 * params.get<double>("kn", Bounds::positive());          // "a real number > 0"
 * params.get_or<double>("restitution", 0.9, Bounds::open_closed(0.0, 1.0));
 * \endcode
 */
struct Bounds {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool lo_open = false;
    bool hi_open = false;

    static Bounds any() { return {}; }
    static Bounds positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
    static Bounds non_negative() { return {0.0, std::numeric_limits<double>::infinity()}; }
    static Bounds at_least(double v) { return {v, std::numeric_limits<double>::infinity()}; }
    static Bounds closed(double a, double b) { return {a, b}; }
    static Bounds open(double a, double b) { return {a, b, true, true}; }
    static Bounds open_closed(double a, double b) { return {a, b, true, false}; }
    static Bounds closed_open(double a, double b) { return {a, b, false, true}; }

    bool contains(double v) const {
        if (lo_open ? !(v > lo) : !(v >= lo)) return false;
        if (hi_open ? !(v < hi) : !(v <= hi)) return false;
        return true;
    }
    bool unbounded() const {
        return lo == -std::numeric_limits<double>::infinity() &&
               hi == std::numeric_limits<double>::infinity();
    }
    /// "> 0", ">= 1", "in (0, 1]", or "" when unbounded.
    std::string describe() const;
    /// The interval itself: "[0, 1000]", "(0, inf)".
    std::string interval() const;
};

}  // namespace efdem
