#pragma once
/// \file
/// Quoting for a POSIX shell: a command line that efdem prints for the user to paste (the
/// restart command after a stop) must run exactly the arguments it names, whatever they hold.

#include <string>
#include <string_view>

namespace efdem {

/// `word` as one POSIX-shell word: unchanged when it holds only characters no shell treats
/// specially (letters, digits and _@%+=:,./-), else in single quotes, each ' written '\''.
/// The empty word is ''.
std::string shell_quote(std::string_view word);

}  // namespace efdem
