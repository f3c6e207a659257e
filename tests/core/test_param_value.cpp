// Typed parameter values on their own, without a table: strict parsing of tokens, bounds, the
// "allowed" wording and how a default is shown in the list of parameters used.
#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "core/param_value.hpp"

using efdem::Bounds;
using efdem::param_value_expected;
using efdem::parse_param_value;
using efdem::show_param_value;
using Tokens = std::vector<std::string>;

namespace {
/// The problem parse_param_value<T> reports for `tokens`, or "" if they parse.
template <class T>
std::string problem_of(const Tokens& tokens, const Bounds& bounds = {}) {
    std::string problem;
    return parse_param_value<T>(tokens, bounds, problem) ? std::string() : problem;
}
}  // namespace

TEST_CASE("values: numbers parse strictly, whole token and finite", "[unit][params]") {
    std::string problem;
    CHECK(parse_param_value<double>({"+2.5"}, {}, problem) == 2.5);
    CHECK(parse_param_value<long>({"1e6"}, {}, problem) == 1'000'000);
    CHECK(problem_of<double>({"2.5x"}) == "is not a number");
    CHECK(problem_of<double>({"1e999"}) == "is out of the range of a double");
    CHECK(problem_of<double>({"inf"}) == "is not a finite number");
    CHECK(problem_of<double>({"0"}, Bounds::positive()) == "is out of range");
    CHECK(problem_of<int>({"2.5"}) == "is not an integer");
    CHECK(problem_of<std::uint64_t>({"-1"}) == "is out of range");
    CHECK(problem_of<bool>({"maybe"}) == "is not a boolean");
    CHECK(parse_param_value<bool>({"Off"}, {}, problem) == false);
}

TEST_CASE("values: arity and the elements of a vector", "[unit][params]") {
    CHECK(problem_of<double>({"1", "2"}) == "expected one value, got 2");
    CHECK(problem_of<std::string>({"a", "b"}) == "expected one word, got 2");
    CHECK(problem_of<efdem::Vec3>({"0", "0"}) == "expected 3 values, got 2");
    CHECK(problem_of<std::vector<double>>({"1", "x"}) == "element 'x' is not a number");
    CHECK(problem_of<std::vector<double>>({"1", "-1"}, Bounds::non_negative()) ==
          "element '-1' is out of range");
    CHECK(problem_of<std::vector<double>>({}) == "has no values");
    CHECK(problem_of<std::vector<std::string>>({}) == "has no values");
}

TEST_CASE("values: what is allowed, and how a value is shown", "[unit][params]") {
    CHECK(param_value_expected<double>(Bounds::positive()) == "a finite real number > 0");
    CHECK(param_value_expected<int>({}) == "an integer from -2147483648 to 2147483647");
    CHECK(param_value_expected<long>(Bounds::at_least(1)) == "an integer >= 1");
    CHECK(param_value_expected<efdem::Vec3>({}) == "three finite real numbers");
    CHECK(param_value_expected<bool>({}) == "true/false, yes/no, on/off or 1/0");
    CHECK(show_param_value(0.9) == "0.9");
    CHECK(show_param_value(true) == "true");
    CHECK(show_param_value(efdem::Vec3{0, 0, -1}) == "0 0 -1");
    CHECK(show_param_value(std::vector<std::string>{"gravity", "pair_contact"}) ==
          "gravity pair_contact");
    CHECK(show_param_value(std::vector<double>{1.5, 2}) == "1.5 2");
}

TEST_CASE("a computed bound is shown as a user would write it", "[unit][params]") {
    // pair_contact.kt's lower bound is 1e-6 x kn: for kn = 2e5 the double is 0.19999999999999998,
    // which the allowed text used to show; 15 significant digits show 0.2 (a double has 15-17,
    // so every bound a user types, e.g. 1e-09 or 1000000, reads as typed).
    CHECK(param_value_expected<double>(Bounds::closed(1e-6 * 2e5, 2e5)) ==
          "a finite real number in [0.2, 200000]");
    CHECK(param_value_expected<double>(Bounds::at_least(1e-09)) == "a finite real number >= 1e-09");
    CHECK(param_value_expected<double>(Bounds::positive()) == "a finite real number > 0");
}
