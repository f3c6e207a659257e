/// \file
/// The scene lexer (see scene_lexer.hpp): lines, comments, key names, quotes.
#include "core/scene_lexer.hpp"

#include <cctype>
#include <map>
#include <sstream>

#include <fmt/format.h>

namespace efdem {

namespace {

std::string_view trim(std::string_view s) {
    const auto is_space = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

bool valid_key(std::string_view key) {
    if (key.empty() || key.front() == '.' || key.back() == '.') return false;
    if (!(std::isalpha(static_cast<unsigned char>(key.front())) || key.front() == '_'))
        return false;
    char prev = 0;
    for (char c : key) {
        const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.';
        if (!ok || (c == '.' && prev == '.')) return false;
        prev = c;
    }
    return true;
}

/// Strips a trailing `#` comment that is not inside double quotes.
std::string_view strip_comment(std::string_view line) {
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        if (line[i] == '"') quoted = !quoted;
        if (line[i] == '#' && !quoted) return line.substr(0, i);
    }
    return line;
}

}  // namespace

SceneAssignment parse_assignment(std::string_view text, SourceLocation where, AssignmentForm form) {
    const auto eq = text.find('=');
    if (eq == std::string_view::npos)
        throw InputError(
            std::move(where),
            fmt::format("expected {}, got '{}'",
                        form == AssignmentForm::scene_line ? "'key = value'" : "key=value",
                        quote_for_message(text)));
    std::string key(trim(text.substr(0, eq)));
    std::string value(trim(text.substr(eq + 1)));
    if (!valid_key(key))
        throw InputError(std::move(where), std::move(key), std::move(value),
                         "is not a valid key name",
                         "letters, digits, '_' and '.', starting with a letter or '_'");
    if (value.empty())
        throw InputError(std::move(where), std::move(key), std::move(value), "has no value");
    if (!split_value(value))
        throw InputError(std::move(where), std::move(key), std::move(value),
                         "has an unterminated quote");
    return {std::move(key), std::move(value), std::move(where)};
}

std::vector<SceneAssignment> lex_scene(std::string_view text, const std::string& file) {
    std::vector<SceneAssignment> out;
    std::map<std::string, int, std::less<>> first_line;  // key -> line of its definition
    std::istringstream in{std::string(text)};
    std::string raw;
    int line_no = 0;
    while (std::getline(in, raw)) {
        ++line_no;
        SourceLocation where{file, line_no};
        if (raw.find('\0') != std::string::npos)
            throw InputError(std::move(where),
                             "the line contains a NUL byte; is this a text file?");
        const std::string_view line = trim(strip_comment(raw));
        if (line.empty()) continue;
        SceneAssignment a = parse_assignment(line, std::move(where), AssignmentForm::scene_line);
        if (const auto it = first_line.find(a.key); it != first_line.end())
            throw InputError(std::move(a.where), std::move(a.key), std::move(a.value),
                             fmt::format("is defined twice (first at line {})", it->second),
                             "one definition per key; override on the command line with key=value");
        first_line.emplace(a.key, line_no);
        out.push_back(std::move(a));
    }
    return out;
}

std::optional<std::vector<std::string>> split_value(std::string_view value) {
    std::vector<std::string> out;
    std::size_t i = 0;
    while (i < value.size()) {
        while (i < value.size() && std::isspace(static_cast<unsigned char>(value[i]))) ++i;
        if (i >= value.size()) break;
        if (value[i] == '"') {
            const std::size_t end = value.find('"', i + 1);
            if (end == std::string_view::npos) return std::nullopt;
            out.emplace_back(value.substr(i + 1, end - i - 1));
            i = end + 1;
        } else {
            std::size_t end = i;
            while (end < value.size() && !std::isspace(static_cast<unsigned char>(value[end])))
                ++end;
            out.emplace_back(value.substr(i, end - i));
            i = end;
        }
    }
    return out;
}

}  // namespace efdem
