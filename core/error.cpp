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
/// Length of the valid UTF-8 sequence starting at s[i] (2 to 4), or 0 if there is none.
std::size_t utf8_sequence(std::string_view s, std::size_t i) {
    const auto b = static_cast<unsigned char>(s[i]);
    const std::size_t len = b >= 0xF0 && b <= 0xF4  ? 4
                            : b >= 0xE0             ? 3
                            : b >= 0xC2 && b < 0xE0 ? 2
                                                    : 0;
    if (len == 0 || b > 0xF4 || i + len > s.size()) return 0;
    for (std::size_t k = 1; k < len; ++k)
        if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
    return len;
}
}  // namespace

std::string quote_for_message(std::string_view text, std::size_t max_chars) {
    std::string out;
    std::size_t shown = 0, i = 0;
    for (; i < text.size() && shown < max_chars; ++shown) {
        const auto b = static_cast<unsigned char>(text[i]);
        if (b >= 0x20 && b < 0x7F) {
            out += text[i++];
        } else if (const std::size_t len = b >= 0x80 ? utf8_sequence(text, i) : 0; len > 0) {
            out.append(text.substr(i, len));
            i += len;
        } else {
            constexpr char kHex[] = "0123456789abcdef";
            out += "\\x";
            out += kHex[b >> 4];
            out += kHex[b & 0xF];
            ++i;
        }
    }
    if (i < text.size()) out += "... (" + std::to_string(text.size()) + " bytes in all)";
    return out;
}

namespace {
std::string format_key_error(const SourceLocation& where, const std::string& key,
                             const std::string& value, const std::string& problem,
                             const std::string& allowed) {
    std::string msg = where.to_string() + ": key '" + quote_for_message(key) + "'";
    if (!value.empty()) msg += " = '" + quote_for_message(value) + "'";
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
