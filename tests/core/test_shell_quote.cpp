#include <catch2/catch.hpp>

#include <cstdio>
#include <string>

#include "core/shell_quote.hpp"

using efdem::shell_quote;

TEST_CASE("shell_quote leaves plain words alone", "[core][shell_quote]") {
    CHECK(shell_quote("output.prefix=run_7") == "output.prefix=run_7");
    CHECK(shell_quote("/scratch/a-b/c.h5") == "/scratch/a-b/c.h5");
}

TEST_CASE("shell_quote makes every other word one inert word", "[core][shell_quote]") {
    CHECK(shell_quote("") == "''");
    CHECK(shell_quote("a b") == "'a b'");
    CHECK(shell_quote("p=$(touch x)") == "'p=$(touch x)'");
    CHECK(shell_quote("it's") == "'it'\\''s'");
}

TEST_CASE("a real shell reads a quoted word back unchanged", "[core][shell_quote]") {
    // The fact that matters: /bin/sh, given the quoted word, prints the original bytes (no
    // expansion, no splitting, no command run).
    for (const std::string word : {"a b", "p=$(echo no)", "x'y\"z", "`id` ; *", "tab\there", ""}) {
        const std::string command = "printf %s " + shell_quote(word);
        FILE* pipe = ::popen(command.c_str(), "r");
        REQUIRE(pipe != nullptr);
        std::string got;
        char buf[256];
        while (const std::size_t n = std::fread(buf, 1, sizeof buf, pipe)) got.append(buf, n);
        REQUIRE(::pclose(pipe) == 0);
        CHECK(got == word);
    }
}
