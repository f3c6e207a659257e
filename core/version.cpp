#include "core/version.hpp"

#include <fmt/format.h>

namespace efdem {
std::string version() {
    return EFDEM_VERSION_STRING;
}
std::string git_hash() {
    return detail::kGitHash;
}
std::string build_info() {
    return fmt::format("g++ {}.{}.{}, {} build{}{}", __GNUC__, __GNUC_MINOR__, __GNUC_PATCHLEVEL__,
                       EFDEM_BUILD_TYPE_STRING, EFDEM_NATIVE_FLAG ? ", -march=native" : "",
                       EFDEM_SANITIZE_FLAG ? ", ASan+UBSan" : "");
}
}  // namespace efdem
