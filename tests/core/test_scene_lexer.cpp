// The scene lexer on its own: lines, comments and quotes to assignments with file:line, and the one
// assignment check that scene lines and command-line overrides share, message by message.
#include <catch2/catch.hpp>

#include <string>
#include <string_view>
#include <vector>

#include "core/scene_lexer.hpp"
#include "tests/support/input_error.hpp"

using efdem::AssignmentForm;
using efdem::lex_scene;
using efdem::parse_assignment;
using efdem::split_value;
using efdem::test::input_error;

using namespace std::string_literals;
using namespace std::string_view_literals;

namespace {
/// The InputError parse_assignment raises for `text` as line 7 of bed.cfg, or as an override.
efdem::InputError scene_line_error(std::string_view text) {
    return input_error([&] { parse_assignment(text, {"bed.cfg", 7}, AssignmentForm::scene_line); });
}
efdem::InputError command_line_error(std::string_view text) {
    return input_error([&] {
        parse_assignment(text, {"<command line>", 0}, AssignmentForm::command_line);
    });
}
}  // namespace

TEST_CASE("lexer: a multi-line scene with comments, blanks and quotes", "[unit][params]") {
    const auto lines = lex_scene(
        "# header comment\n"
        "\n"
        "dt = 1e-4   # trailing comment\n"
        "   effects=gravity pair_contact\n"
        "name = \"a # b\"  # the first '#' is quoted\n"
        "\t\n"
        "gravity.g = 0 0 -1\n",
        "bed.cfg");
    REQUIRE(lines.size() == 4);
    CHECK(lines[0].key == "dt");
    CHECK(lines[0].value == "1e-4");
    CHECK(lines[0].where.file == "bed.cfg");
    CHECK(lines[0].where.line == 3);
    CHECK(lines[1].key == "effects");
    CHECK(lines[1].value == "gravity pair_contact");
    CHECK(lines[1].where.line == 4);
    CHECK(lines[2].value == "\"a # b\"");  // the value stays raw text, quotes and all
    CHECK(lines[2].where.line == 5);
    CHECK(lines[3].key == "gravity.g");
    CHECK(lines[3].where.line == 7);
    CHECK(lex_scene("# only a comment\n\n", "bed.cfg").empty());
}

TEST_CASE("lexer: the first bad line is reported, with its exact message", "[unit][params]") {
    CHECK(input_error([] { lex_scene("dt = 1\n\ndt = 2\n", "bed.cfg"); }).what() ==
          "bed.cfg:3: key 'dt' = '2': is defined twice (first at line 1) (allowed: one "
          "definition per key; override on the command line with key=value)"s);
    CHECK(input_error([] { lex_scene("dt = 1\nab\0c = 2\n"sv, "bed.cfg"); }).what() ==
          "bed.cfg:2: the line contains a NUL byte; is this a text file?"s);
    // A syntax error on an earlier line wins over a duplicate on a later one.
    CHECK(input_error([] { lex_scene("dt = 1\nbad\ndt = 2\n", "bed.cfg"); }).where().line == 2);
}

TEST_CASE("assignment check: one set of messages for scene lines and the command line",
          "[unit][params]") {
    SECTION("a good assignment is split and trimmed") {
        const auto a = parse_assignment(" pair_contact.kn =  2e5 ", {"bed.cfg", 7},
                                        AssignmentForm::scene_line);
        CHECK(a.key == "pair_contact.kn");
        CHECK(a.value == "2e5");
        CHECK(a.where.line == 7);
    }
    SECTION("no '=': the form is spelt as the user would write it there") {
        CHECK(scene_line_error("dt 1e-4").what() ==
              "bed.cfg:7: expected 'key = value', got 'dt 1e-4'"s);
        CHECK(command_line_error("justaword").what() ==
              "<command line>: expected key=value, got 'justaword'"s);
    }
    SECTION("a bad key name") {
        for (const char* bad : {"1dt = 3", ".dt = 3", "dt. = 3", "a..b = 3", "d-t = 3", " = 3"})
            CHECK(scene_line_error(bad).problem() == "is not a valid key name");
        const std::string allowed =
            " (allowed: letters, digits, '_' and '.', starting with a letter or '_')";
        CHECK(command_line_error("1dt=3").what() ==
              "<command line>: key '1dt' = '3': is not a valid key name" + allowed);
        CHECK(scene_line_error("1dt = 3").what() ==
              "bed.cfg:7: key '1dt' = '3': is not a valid key name" + allowed);
    }
    SECTION("a bad value") {
        CHECK(scene_line_error("name = \"open").what() ==
              "bed.cfg:7: key 'name' = '\"open': has an unterminated quote"s);
        CHECK(command_line_error("dt=").what() == "<command line>: key 'dt': has no value"s);
    }
}

TEST_CASE("value tokens: whitespace splits, double quotes group", "[unit][params]") {
    CHECK(split_value("0 0\t-1") == std::vector<std::string>{"0", "0", "-1"});
    CHECK(split_value("\"two words\" three") == std::vector<std::string>{"two words", "three"});
    CHECK(split_value("\"\"") == std::vector<std::string>{""});
    CHECK(split_value("   ") == std::vector<std::string>{});
    CHECK_FALSE(split_value("a \"b c").has_value());
}
