/// \file
/// Typed parameter values (see param_value.hpp): strict number, integer and boolean parsing and
/// the per-type rules (arity, bounds, how the expected value is described, how a value is shown).
#include "core/param_value.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <string_view>

#include <fmt/format.h>

#include "core/error.hpp"

namespace efdem {

namespace {

// ---------------------------------------------------------------------------------------------
// Strict token parsing. Each parser returns nullopt and fills `problem` on failure.

std::optional<double> parse_real(const std::string& tok, std::string& problem) {
    double v = 0.0;
    const char* first = tok.data();
    const char* last = tok.data() + tok.size();
    if (!tok.empty() && tok.front() == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, v);
    if (ec == std::errc::result_out_of_range) {
        problem = "is out of the range of a double";
        return std::nullopt;
    }
    if (ec != std::errc() || ptr != last || first == last) {
        problem = "is not a number";
        return std::nullopt;
    }
    if (!std::isfinite(v)) {
        problem = "is not a finite number";
        return std::nullopt;
    }
    return v;
}

template <class Int>
std::optional<Int> parse_integer(const std::string& tok, std::string& problem) {
    Int v{};
    const char* first = tok.data();
    const char* last = tok.data() + tok.size();
    if (!tok.empty() && tok.front() == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, v);
    if (ec == std::errc() && ptr == last && first != last) return v;
    // Accept integral values written as reals ("1e6", "2.0"): users write step counts that way.
    // The range test is against powers of two, which doubles hold exactly: max() itself rounds
    // up to 2^digits as a double, and converting 2^digits back to Int would be undefined.
    std::string real_problem;
    const auto r = parse_real(tok, real_problem);
    const double lo = static_cast<double>(std::numeric_limits<Int>::min());
    const double hi_excl = std::ldexp(1.0, std::numeric_limits<Int>::digits);
    if (r && std::trunc(*r) == *r && *r >= lo && *r < hi_excl) return static_cast<Int>(*r);
    problem = (r && std::trunc(*r) == *r) ? "is out of range" : "is not an integer";
    return std::nullopt;
}

std::optional<bool> parse_bool(const std::string& tok, std::string& problem) {
    std::string t = tok;
    std::transform(t.begin(), t.end(), t.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (t == "true" || t == "yes" || t == "on" || t == "1") return true;
    if (t == "false" || t == "no" || t == "off" || t == "0") return false;
    problem = "is not a boolean";
    return std::nullopt;
}

std::string with_bounds(std::string what, const Bounds& b) {
    const std::string d = b.describe();
    return d.empty() ? what : what + " " + d;
}

/// True if there are `n` tokens; otherwise sets `problem` ("expected one value, got 2").
bool has_count(const std::vector<std::string>& toks, std::size_t n, std::string_view what,
               std::string& problem) {
    if (toks.size() == n) return true;
    problem = fmt::format("expected {}, got {}", what, toks.size());
    return false;
}

/// The rules of one value type: parse tokens into T, describe what is expected, show a value.
template <class T>
struct ValueTraits;

template <>
struct ValueTraits<double> {
    static std::string expected(const Bounds& b) { return with_bounds("a finite real number", b); }
    static std::optional<double> parse(const std::vector<std::string>& toks, const Bounds& b,
                                       std::string& problem) {
        if (!has_count(toks, 1, "one value", problem)) return std::nullopt;
        auto v = parse_real(toks[0], problem);
        if (v && !b.contains(*v)) {
            problem = "is out of range";
            return std::nullopt;
        }
        return v;
    }
    static std::string show(double v) { return fmt::format("{}", v); }
};

template <class Int>
struct IntTraits {
    static std::string expected(const Bounds& b) {
        if (b.unbounded())
            return fmt::format("an integer from {} to {}", std::numeric_limits<Int>::min(),
                               std::numeric_limits<Int>::max());
        return with_bounds("an integer", b);
    }
    static std::optional<Int> parse(const std::vector<std::string>& toks, const Bounds& b,
                                    std::string& problem) {
        if (!has_count(toks, 1, "one value", problem)) return std::nullopt;
        auto v = parse_integer<Int>(toks[0], problem);
        if (v && !b.contains(static_cast<double>(*v))) {
            problem = "is out of range";
            return std::nullopt;
        }
        return v;
    }
    static std::string show(Int v) { return fmt::format("{}", v); }
};
template <>
struct ValueTraits<int> : IntTraits<int> {};
template <>
struct ValueTraits<long> : IntTraits<long> {};
template <>
struct ValueTraits<std::uint64_t> : IntTraits<std::uint64_t> {};

template <>
struct ValueTraits<bool> {
    static std::string expected(const Bounds&) { return "true/false, yes/no, on/off or 1/0"; }
    static std::optional<bool> parse(const std::vector<std::string>& toks, const Bounds&,
                                     std::string& problem) {
        if (!has_count(toks, 1, "one value", problem)) return std::nullopt;
        return parse_bool(toks[0], problem);
    }
    static std::string show(bool v) { return v ? "true" : "false"; }
};

template <>
struct ValueTraits<std::string> {
    static std::string expected(const Bounds&) { return "one word (quote it if it has spaces)"; }
    static std::optional<std::string> parse(const std::vector<std::string>& toks, const Bounds&,
                                            std::string& problem) {
        if (!has_count(toks, 1, "one word", problem)) return std::nullopt;
        return toks[0];
    }
    static std::string show(const std::string& v) { return v; }
};

template <>
struct ValueTraits<std::vector<double>> {
    static std::string expected(const Bounds& b) {
        return with_bounds("one or more finite real numbers", b);
    }
    static std::optional<std::vector<double>> parse(const std::vector<std::string>& toks,
                                                    const Bounds& b, std::string& problem) {
        std::vector<double> out;
        for (const auto& t : toks) {
            auto v = parse_real(t, problem);
            if (!v) {
                problem = fmt::format("element '{}' {}", quote_for_message(t, 40), problem);
                return std::nullopt;
            }
            if (!b.contains(*v)) {
                problem = fmt::format("element '{}' is out of range", quote_for_message(t, 40));
                return std::nullopt;
            }
            out.push_back(*v);
        }
        if (out.empty()) {
            problem = "has no values";
            return std::nullopt;
        }
        return out;
    }
    static std::string show(const std::vector<double>& v) {
        return fmt::format("{}", fmt::join(v, " "));
    }
};

template <>
struct ValueTraits<std::vector<std::string>> {
    static std::string expected(const Bounds&) { return "one or more words"; }
    static std::optional<std::vector<std::string>> parse(const std::vector<std::string>& toks,
                                                         const Bounds&, std::string& problem) {
        if (toks.empty()) {
            problem = "has no values";
            return std::nullopt;
        }
        return toks;
    }
    static std::string show(const std::vector<std::string>& v) {
        return fmt::format("{}", fmt::join(v, " "));
    }
};

template <>
struct ValueTraits<Vec3> {
    static std::string expected(const Bounds& b) {
        return with_bounds("three finite real numbers", b);
    }
    static std::optional<Vec3> parse(const std::vector<std::string>& toks, const Bounds& b,
                                     std::string& problem) {
        if (!has_count(toks, 3, "3 values", problem)) return std::nullopt;
        auto v = ValueTraits<std::vector<double>>::parse(toks, b, problem);
        if (!v) return std::nullopt;
        return Vec3{(*v)[0], (*v)[1], (*v)[2]};
    }
    static std::string show(const Vec3& v) { return fmt::format("{} {} {}", v.x, v.y, v.z); }
};

}  // namespace

template <class T>
std::optional<T> parse_param_value(const std::vector<std::string>& tokens, const Bounds& bounds,
                                   std::string& problem) {
    return ValueTraits<T>::parse(tokens, bounds, problem);
}

template <class T>
std::string param_value_expected(const Bounds& bounds) {
    return ValueTraits<T>::expected(bounds);
}

template <class T>
std::string show_param_value(const T& value) {
    return ValueTraits<T>::show(value);
}

#define EFDEM_PARAM_VALUE_INSTANTIATE(T)                                                           \
    template std::optional<T> parse_param_value<T>(const std::vector<std::string>&, const Bounds&, \
                                                   std::string&);                                  \
    template std::string param_value_expected<T>(const Bounds&);                                   \
    template std::string show_param_value<T>(const T&);
EFDEM_PARAM_VALUE_TYPES(EFDEM_PARAM_VALUE_INSTANTIATE)
#undef EFDEM_PARAM_VALUE_INSTANTIATE

}  // namespace efdem
