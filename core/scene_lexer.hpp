#pragma once
/// \file
/// The scene lexer: scene text to `key = value` assignments with their file:line, and the one
/// syntax check of an assignment that the scene file and the command line share.
///
/// What is syntax here: a line is `key = value` after a `#` comment (outside double quotes) is
/// cut off; a key is letters, digits, '_' and '.' starting with a letter or '_', without empty
/// scopes; a value is one or more whitespace-separated tokens, a token may be double-quoted to
/// hold spaces. What a value means (a number, a word, a path) is for core/param_value.hpp to say,
/// and which keys are read for core/param_table.hpp.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.hpp"

namespace efdem {

/// One `key = value` as written: key and value trimmed, the value still raw text.
struct SceneAssignment {
    std::string key;
    std::string value;
    SourceLocation where;
};

/// Where an assignment was written. Only the wording of the "expected ..." message differs:
/// a scene line is shown the spaced form `'key = value'`, a command-line word `key=value`.
enum class AssignmentForm { scene_line, command_line };

/// Checks one assignment's syntax and splits it into key and value. `text` is the assignment
/// as written (for a scene line: comment already cut off, trimmed). Throws InputError at `where`
/// if there is no '=', the key is not a valid key name, the value is empty or has an
/// unterminated quote.
SceneAssignment parse_assignment(std::string_view text, SourceLocation where, AssignmentForm form);

/// Lexes a whole scene: one assignment per non-blank line, in file order, each located at
/// `file`:line. Throws InputError on the first bad line (a NUL byte, a syntax error as in
/// parse_assignment, a key already defined on an earlier line).
std::vector<SceneAssignment> lex_scene(std::string_view text, const std::string& file);

/// Splits a value into its whitespace-separated tokens; "..." is one token without the quotes.
/// nullopt on an unterminated quote.
std::optional<std::vector<std::string>> split_value(std::string_view value);

}  // namespace efdem
