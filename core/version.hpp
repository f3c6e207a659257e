#pragma once
/// \file
/// Build provenance written into every output file and printed by `efdem --version`.

#include <string>

namespace efdem {
std::string version();    ///< "0.1.0"
std::string git_hash();   ///< short hash of the source tree at configure time, or "unknown"
std::string build_info(); ///< compiler, build type, options
}  // namespace efdem
