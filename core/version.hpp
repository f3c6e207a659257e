#pragma once
/// \file
/// Build provenance written into every output file and printed by `efdem --version`.

#include <string>

namespace efdem {
std::string version();  ///< "0.1.0"
/// Short hash of HEAD when the build ran, with "-dirty" if tracked files differed; "unknown"
/// outside a git checkout.
std::string git_hash();
std::string build_info();  ///< compiler, build type, options

namespace detail {
extern const char* const kGitHash;  ///< defined in the build tree's git_hash.cpp
}
}  // namespace efdem
