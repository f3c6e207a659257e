// ParamTable / Params: the scene-file reader. One test per error kind a user can make, and the
// behaviours the rest of efdem relies on (overrides win, defaults recorded, scopes, paths).
#include <catch2/catch.hpp>

#include <limits>
#include <string>

#include "core/param_table.hpp"
#include "tests/support/input_error.hpp"

using efdem::Bounds;
using efdem::InputError;
using efdem::ParamTable;
using efdem::test::input_error;

namespace {
ParamTable scene(const char* text) {
    return ParamTable::from_text(text, "bed.cfg", "/scenes");
}

}  // namespace

TEST_CASE("scene text parses keys, vectors, comments and quoted words", "[unit][params]") {
    auto t = scene(
        "# a comment line\n"
        "dt = 1e-4   # trailing comment\n"
        "effects = gravity pair_contact\n"
        "gravity.g = 0 0 -1\n"
        "name = \"two words\"\n"
        "flag = yes\n"
        "count = 1e3\n");
    auto p = t.root();
    CHECK(p.get<double>("dt") == 1e-4);
    CHECK(p.get<std::vector<std::string>>("effects") ==
          std::vector<std::string>{"gravity", "pair_contact"});
    CHECK(t.scope("gravity").get<efdem::Vec3>("g") == efdem::Vec3{0, 0, -1});
    CHECK(p.get<std::string>("name") == "two words");
    CHECK(p.get<bool>("flag"));
    CHECK(p.get<long>("count") == 1000);  // integral reals are accepted as integers
    CHECK_NOTHROW(t.check_all_used());
}

TEST_CASE("command-line overrides win over the file and are recorded as such", "[unit][params]") {
    auto t = scene("dt = 1e-4\nseed = 1\n");
    t.add_override("seed=42");
    t.add_override("output.directory=runs/a");
    auto p = t.root();
    CHECK(p.get<std::uint64_t>("seed") == 42);
    CHECK(p.location("seed").file == "<command line>");
    // A relative path from the command line resolves against the working directory ...
    CHECK(t.scope("output").get_path("directory") == std::filesystem::path("runs/a"));
    p.get<double>("dt");
    CHECK_NOTHROW(t.check_all_used());
}

TEST_CASE("relative paths written in the scene resolve against the scene's folder",
          "[unit][params]") {
    auto t = scene("bed.file = data/bed.data.gz\nabs = /tmp/x\n");
    CHECK(t.scope("bed").get_path("file") == std::filesystem::path("/scenes/data/bed.data.gz"));
    CHECK(t.root().get_path("abs") == std::filesystem::path("/tmp/x"));
}

TEST_CASE("optional keys record the default that was used", "[unit][params]") {
    auto t = scene("dt = 1e-4\n");
    auto p = t.root();
    CHECK(p.get_or<double>("pair_contact.restitution", 0.9) == 0.9);
    p.get<double>("dt");
    bool found = false;
    for (const auto& r : t.resolved())
        if (r.key == "pair_contact.restitution") {
            found = true;
            CHECK(r.origin == "default");
            CHECK(r.value == "0.9");
        }
    CHECK(found);
}

TEST_CASE("error: a non-numeric value names file, line, key, value and what is allowed",
          "[unit][params]") {
    auto t = scene("dt = 1e-4\npair_contact.kn = abc\n");
    const auto e =
        input_error([&] { t.scope("pair_contact").get<double>("kn", Bounds::positive()); });
    CHECK(e.where().file == "bed.cfg");
    CHECK(e.where().line == 2);
    CHECK(e.key() == "pair_contact.kn");
    CHECK(e.value() == "abc");
    CHECK(e.problem() == "is not a number");
    CHECK(e.allowed() == "a finite real number > 0");
    CHECK(std::string(e.what()) ==
          "bed.cfg:2: key 'pair_contact.kn' = 'abc': is not a number "
          "(allowed: a finite real number > 0)");
}

TEST_CASE("error: out-of-range, non-finite, wrong arity and non-integer values", "[unit][params]") {
    auto t = scene("a = -5\nb = nan\nc = 1 2\nd = 2.5\ne = maybe\ng = 0 0\n");
    auto p = t.root();
    CHECK(input_error([&] { p.get<double>("a", Bounds::positive()); }).problem() ==
          "is out of range");
    CHECK(input_error([&] { p.get<double>("b"); }).problem() == "is not a finite number");
    CHECK(input_error([&] { p.get<double>("c"); }).problem() == "expected one value, got 2");
    CHECK(input_error([&] { p.get<int>("d"); }).problem() == "is not an integer");
    CHECK(input_error([&] { p.get<bool>("e"); }).problem() == "is not a boolean");
    CHECK(input_error([&] { p.get<efdem::Vec3>("g"); }).problem() == "expected 3 values, got 2");
}

TEST_CASE("error: a missing required key suggests a misspelt one", "[unit][params]") {
    auto t = scene("dt = 1e-4\npair_contact.kN = 2e5\n");
    const auto e = input_error([&] { t.scope("pair_contact").get<double>("kn"); });
    CHECK(e.key() == "pair_contact.kn");
    CHECK(e.problem() == "is required but missing; did you mean 'pair_contact.kN' at bed.cfg:2?");
}

TEST_CASE("error: an unused key is named, with the closest key that was read", "[unit][params]") {
    auto t = scene("dt = 1e-4\nsed = 3\n");
    auto p = t.root();
    p.get<double>("dt");
    p.get_or<std::uint64_t>("seed", 1);
    const auto e = input_error([&] { t.check_all_used(); });
    CHECK(e.where().line == 2);
    CHECK(e.key() == "sed");
    CHECK(e.problem() == "was never read: did you mean 'seed'?");
}

TEST_CASE("error: an unused key gets the caller's hint", "[unit][params]") {
    auto t = scene("gas_drag.law = wen_yu_low_re\n");
    const auto e = input_error([&] {
        t.check_all_used([](const efdem::ParamEntry& entry) {
            return entry.key.rfind("gas_drag.", 0) == 0 ? "is 'gas_drag' listed in 'effects'?" : "";
        });
    });
    CHECK(e.key() == "gas_drag.law");
    CHECK(e.problem() == "was never read: is 'gas_drag' listed in 'effects'?");
}

TEST_CASE("error: a word not in the allowed list lists the allowed words", "[unit][params]") {
    auto t = scene("mode = fast\n");
    const auto e = input_error([&] { t.root().get_choice("mode", {"direct", "cpi"}); });
    CHECK(e.allowed() == "direct, cpi");
    CHECK(e.where().line == 1);
}

TEST_CASE("error: syntax errors, bad key names and duplicates", "[unit][params]") {
    CHECK(input_error([] { scene("dt 1e-4\n"); }).problem() ==
          "expected 'key = value', got 'dt 1e-4'");
    CHECK(input_error([] { scene("1dt = 3\n"); }).problem() == "is not a valid key name");
    CHECK(input_error([] { scene("dt =\n"); }).problem() == "has no value");
    CHECK(input_error([] { scene("name = \"open\n"); }).problem() == "has an unterminated quote");
    const auto dup = input_error([] { scene("dt = 1\n\ndt = 2\n"); });
    CHECK(dup.where().line == 3);
    CHECK(dup.problem() == "is defined twice (first at line 1)");
    CHECK(input_error([] {
              auto t = scene("dt = 1\n");
              t.add_override("justaword");
          })
              .where()
              .file == "<command line>");
}

TEST_CASE("a missing scene file is an input error naming the file", "[unit][params]") {
    const auto e = input_error([] { ParamTable::from_file("/nonexistent/scene.cfg"); });
    CHECK(e.where().file == "/nonexistent/scene.cfg");
    CHECK(e.problem() == "file not found");
}

TEST_CASE("integers at the edge of their type are converted or refused, never wrapped",
          "[unit][params]") {
    // 2^63 and 2^64 are what LONG_MAX and UINT64_MAX round to as doubles; converting them back
    // would be undefined behaviour (the scene fuzzer's "9.3e18" seed).
    auto t = scene(
        "a = 9223372036854775807\nb = 9.3e18\nc = 9223372036854775808\n"
        "d = 1.8446744073709552e19\ne = 18446744073709551615\nf = -1\ng = 2147483648\n");
    auto p = t.root();
    CHECK(p.get<long>("a") == std::numeric_limits<long>::max());
    CHECK(input_error([&] { p.get<long>("b"); }).problem() == "is out of range");
    CHECK(input_error([&] { p.get<long>("c"); }).problem() == "is out of range");
    CHECK(input_error([&] { p.get<std::uint64_t>("d"); }).problem() == "is out of range");
    CHECK(p.get<std::uint64_t>("b") == 9'300'000'000'000'000'000ULL);
    CHECK(p.get<std::uint64_t>("e") == std::numeric_limits<std::uint64_t>::max());
    const auto neg = input_error([&] { p.get<std::uint64_t>("f"); });
    CHECK(neg.allowed() == "an integer from 0 to 18446744073709551615");
    CHECK(input_error([&] { p.get<int>("g"); }).problem() == "is out of range");
}

TEST_CASE("messages quote runaway or binary input safely", "[unit][params]") {
    SECTION("control bytes and invalid UTF-8 are escaped; valid UTF-8 is kept") {
        CHECK(efdem::quote_for_message("a\x1b[31mb") == "a\\x1b[31mb");
        CHECK(efdem::quote_for_message("x\xff\xc3\x28y") == "x\\xff\\xc3(y");
        CHECK(efdem::quote_for_message("caf\xc3\xa9") == "caf\xc3\xa9");
    }
    SECTION("a long value is cut and its length given") {
        const std::string value(1'000'000, '9');
        auto t = scene(("dt = " + value + "\n").c_str());
        const auto e = input_error([&] { t.root().get<double>("dt"); });
        CHECK(std::string(e.what()).size() < 400);
        CHECK(std::string(e.what()).find("(1000000 bytes in all)") != std::string::npos);
        CHECK(e.value() == value);  // the exception still carries the whole value
    }
    SECTION("a long line without '=' and a long unused key") {
        const std::string junk(500'000, 'y');
        const auto e = input_error([&] { scene(("dt = 1\n" + junk + "\n").c_str()); });
        CHECK(std::string(e.what()).size() < 400);
        auto t = scene(("dt = 1\n" + std::string(200'000, 'k') + " = 1\n").c_str());
        t.root().get<double>("dt");
        CHECK(std::string(input_error([&] { t.check_all_used(); }).what()).size() < 600);
    }
    SECTION("many unused keys: the first is named, the rest counted and a few listed") {
        std::string text = "dt = 1\n";
        for (int k = 0; k < 1000; ++k) text.append("x").append(std::to_string(k)).append(" = 1\n");
        auto t = scene(text.c_str());
        t.root().get<double>("dt");
        const auto e = input_error([&] { t.check_all_used(); });
        CHECK(e.key() == "x0");
        CHECK(e.problem().find("999 more unused: x1, x2") != std::string::npos);
        CHECK(std::string(e.what()).size() < 600);
    }
}
