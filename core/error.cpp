#include "core/error.hpp"

#include <cstdio>
#include <cstdlib>

#include "core/contracts.hpp"

namespace efdem {

std::string SourceLocation::to_string() const {
    if (file.empty()) return "<input>";
    if (line <= 0) return file;
    return file + ":" + std::to_string(line);
}

namespace {
std::string format_key_error(const SourceLocation& where, const std::string& key,
                             const std::string& value, const std::string& problem,
                             const std::string& allowed) {
    std::string msg = where.to_string() + ": key '" + key + "'";
    if (!value.empty()) msg += " = '" + value + "'";
    msg += ": " + problem;
    if (!allowed.empty()) msg += " (allowed: " + allowed + ")";
    return msg;
}
}  // namespace

InputError::InputError(SourceLocation where, std::string key, std::string value,
                       std::string problem, std::string allowed)
    : std::runtime_error(format_key_error(where, key, value, problem, allowed)),
      where_(std::move(where)),
      key_(std::move(key)),
      value_(std::move(value)),
      problem_(std::move(problem)),
      allowed_(std::move(allowed)) {}

InputError::InputError(SourceLocation where, std::string problem)
    : std::runtime_error(where.to_string() + ": " + problem),
      where_(std::move(where)),
      problem_(std::move(problem)) {}

namespace detail {
void contract_violation(const char* kind, const char* condition, const char* file,
                        int line) noexcept {
    std::fprintf(stderr, "efdem: internal error (%s violated): %s at %s:%d\n", kind, condition,
                 file, line);
    std::fflush(stderr);
    std::abort();
}
}  // namespace detail

}  // namespace efdem
