#pragma once
/// \file
/// Typed parameter values: the tokens of one value (core/scene_lexer.hpp) to a double, an
/// integer, a bool, a word, a Vec3 or a vector, strictly, with Bounds checked, and back to text.
///
/// Strict means: the whole token is the number (no trailing garbage), numbers are finite,
/// integers may be written as integral reals ("1e6") but are never wrapped, and the arity is
/// right (one token for a scalar, three for a Vec3, at least one for a vector).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/bounds.hpp"
#include "core/vec3.hpp"

namespace efdem {

/// The types a parameter can have, listed once: X(T) for each (used for explicit instantiation
/// here and of Params::get / get_or).
#define EFDEM_PARAM_VALUE_TYPES(X) \
    X(double)                      \
    X(int)                         \
    X(long)                        \
    X(std::uint64_t)               \
    X(bool)                        \
    X(std::string)                 \
    X(Vec3)                        \
    X(std::vector<double>)         \
    X(std::vector<std::string>)

/// Parses the tokens of a value as a T within `bounds` (ignored for bool and words). On failure
/// returns nullopt and sets `problem` to what is wrong, as a message puts it after the key
/// ("is not a number", "expected 3 values, got 2", "element 'x' is out of range").
template <class T>
std::optional<T> parse_param_value(const std::vector<std::string>& tokens, const Bounds& bounds,
                                   std::string& problem);

/// What a value of type T within `bounds` must look like, for a message's "(allowed: ...)".
template <class T>
std::string param_value_expected(const Bounds& bounds);

/// A value as the list of parameters used shows it (a default, for instance).
template <class T>
std::string show_param_value(const T& value);

}  // namespace efdem
