#include "core/param_table.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
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
    if (!(std::isalpha(static_cast<unsigned char>(key.front())) || key.front() == '_')) return false;
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

/// Splits a value into whitespace-separated tokens; "..." is one token without the quotes.
/// Returns nullopt on an unterminated quote.
std::optional<std::vector<std::string>> tokenize(std::string_view value) {
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

std::size_t edit_distance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        cur[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                              std::tolower(static_cast<unsigned char>(b[j - 1]));
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (same ? 0 : 1)});
        }
        std::swap(prev, cur);
    }
    return prev[b.size()];
}

// ---------------------------------------------------------------------------------------------
// Strict value parsing. Each parser returns nullopt and fills `problem`/`expected` on failure.

std::optional<double> parse_real(const std::string& tok, std::string& problem) {
    double v = 0.0;
    const char* first = tok.data();
    const char* last = tok.data() + tok.size();
    if (!tok.empty() && tok.front() == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, v);
    if (ec == std::errc::result_out_of_range) {
        problem = "is out of the range of a double";
        return std::nullopt;
    }
    if (ec != std::errc() || ptr != last || first == last) {
        problem = "is not a number";
        return std::nullopt;
    }
    if (!std::isfinite(v)) {
        problem = "is not a finite number";
        return std::nullopt;
    }
    return v;
}

template <class Int>
std::optional<Int> parse_integer(const std::string& tok, std::string& problem) {
    Int v{};
    const char* first = tok.data();
    const char* last = tok.data() + tok.size();
    if (!tok.empty() && tok.front() == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, v);
    if (ec == std::errc() && ptr == last && first != last) return v;
    // Accept integral values written as reals ("1e6", "2.0"): users write step counts that way.
    // The range test is against powers of two, which doubles hold exactly: max() itself rounds
    // up to 2^digits as a double, and converting 2^digits back to Int would be undefined.
    std::string real_problem;
    const auto r = parse_real(tok, real_problem);
    const double lo = static_cast<double>(std::numeric_limits<Int>::min());
    const double hi_excl = std::ldexp(1.0, std::numeric_limits<Int>::digits);
    if (r && std::trunc(*r) == *r && *r >= lo && *r < hi_excl) return static_cast<Int>(*r);
    problem = (r && std::trunc(*r) == *r) ? "is out of range" : "is not an integer";
    return std::nullopt;
}

std::optional<bool> parse_bool(const std::string& tok, std::string& problem) {
    std::string t = tok;
    std::transform(t.begin(), t.end(), t.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (t == "true" || t == "yes" || t == "on" || t == "1") return true;
    if (t == "false" || t == "no" || t == "off" || t == "0") return false;
    problem = "is not a boolean";
    return std::nullopt;
}

std::string join(const std::vector<std::string>& words, std::string_view sep = ", ") {
    std::string out;
    for (std::size_t i = 0; i < words.size(); ++i) {
        if (i) out += sep;
        out += words[i];
    }
    return out;
}

std::string with_bounds(std::string what, const Bounds& b) {
    const std::string d = b.describe();
    return d.empty() ? what : what + " " + d;
}

/// Type traits for Params::get<T>: parse tokens into T and describe what is expected.
template <class T>
struct ValueTraits;

template <>
struct ValueTraits<double> {
    static std::string expected(const Bounds& b) { return with_bounds("a finite real number", b); }
    static std::optional<double> parse(const std::vector<std::string>& toks, const Bounds& b,
                                       std::string& problem) {
        if (toks.size() != 1) {
            problem = fmt::format("expected one value, got {}", toks.size());
            return std::nullopt;
        }
        auto v = parse_real(toks[0], problem);
        if (v && !b.contains(*v)) {
            problem = "is out of range";
            return std::nullopt;
        }
        return v;
    }
    static std::string show(double v) { return fmt::format("{}", v); }
};

template <class Int>
struct IntTraits {
    static std::string expected(const Bounds& b) {
        if (b.unbounded())
            return fmt::format("an integer from {} to {}", std::numeric_limits<Int>::min(),
                               std::numeric_limits<Int>::max());
        return with_bounds("an integer", b);
    }
    static std::optional<Int> parse(const std::vector<std::string>& toks, const Bounds& b,
                                    std::string& problem) {
        if (toks.size() != 1) {
            problem = fmt::format("expected one value, got {}", toks.size());
            return std::nullopt;
        }
        auto v = parse_integer<Int>(toks[0], problem);
        if (v && !b.contains(static_cast<double>(*v))) {
            problem = "is out of range";
            return std::nullopt;
        }
        return v;
    }
    static std::string show(Int v) { return fmt::format("{}", v); }
};
template <>
struct ValueTraits<int> : IntTraits<int> {};
template <>
struct ValueTraits<long> : IntTraits<long> {};
template <>
struct ValueTraits<std::uint64_t> : IntTraits<std::uint64_t> {};

template <>
struct ValueTraits<bool> {
    static std::string expected(const Bounds&) { return "true/false, yes/no, on/off or 1/0"; }
    static std::optional<bool> parse(const std::vector<std::string>& toks, const Bounds&,
                                     std::string& problem) {
        if (toks.size() != 1) {
            problem = fmt::format("expected one value, got {}", toks.size());
            return std::nullopt;
        }
        return parse_bool(toks[0], problem);
    }
    static std::string show(bool v) { return v ? "true" : "false"; }
};

template <>
struct ValueTraits<std::string> {
    static std::string expected(const Bounds&) { return "one word (quote it if it has spaces)"; }
    static std::optional<std::string> parse(const std::vector<std::string>& toks, const Bounds&,
                                            std::string& problem) {
        if (toks.size() != 1) {
            problem = fmt::format("expected one word, got {}", toks.size());
            return std::nullopt;
        }
        return toks[0];
    }
    static std::string show(const std::string& v) { return v; }
};

template <>
struct ValueTraits<std::vector<double>> {
    static std::string expected(const Bounds& b) {
        return with_bounds("one or more finite real numbers", b);
    }
    static std::optional<std::vector<double>> parse(const std::vector<std::string>& toks,
                                                    const Bounds& b, std::string& problem) {
        std::vector<double> out;
        for (const auto& t : toks) {
            auto v = parse_real(t, problem);
            if (!v) {
                problem = fmt::format("element '{}' {}", quote_for_message(t, 40), problem);
                return std::nullopt;
            }
            if (!b.contains(*v)) {
                problem = fmt::format("element '{}' is out of range", quote_for_message(t, 40));
                return std::nullopt;
            }
            out.push_back(*v);
        }
        if (out.empty()) {
            problem = "has no values";
            return std::nullopt;
        }
        return out;
    }
    static std::string show(const std::vector<double>& v) {
        return fmt::format("{}", fmt::join(v, " "));
    }
};

template <>
struct ValueTraits<std::vector<std::string>> {
    static std::string expected(const Bounds&) { return "one or more words"; }
    static std::optional<std::vector<std::string>> parse(const std::vector<std::string>& toks,
                                                         const Bounds&, std::string& problem) {
        if (toks.empty()) {
            problem = "has no values";
            return std::nullopt;
        }
        return toks;
    }
    static std::string show(const std::vector<std::string>& v) { return join(v, " "); }
};

template <>
struct ValueTraits<Vec3> {
    static std::string expected(const Bounds& b) { return with_bounds("three finite real numbers", b); }
    static std::optional<Vec3> parse(const std::vector<std::string>& toks, const Bounds& b,
                                     std::string& problem) {
        if (toks.size() != 3) {
            problem = fmt::format("expected 3 values, got {}", toks.size());
            return std::nullopt;
        }
        auto v = ValueTraits<std::vector<double>>::parse(toks, b, problem);
        if (!v) return std::nullopt;
        return Vec3{(*v)[0], (*v)[1], (*v)[2]};
    }
    static std::string show(const Vec3& v) { return fmt::format("{} {} {}", v.x, v.y, v.z); }
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// ParamTable

ParamTable ParamTable::from_text(std::string_view text, std::string file,
                                 std::filesystem::path base_dir) {
    ParamTable t;
    t.text_ = std::string(text);
    t.file_ = std::move(file);
    t.base_dir_ = std::move(base_dir);
    std::istringstream in{std::string(text)};
    std::string raw;
    int line_no = 0;
    while (std::getline(in, raw)) {
        ++line_no;
        const SourceLocation where{t.file_, line_no};
        if (raw.find('\0') != std::string::npos)
            throw InputError(where, "the line contains a NUL byte; is this a text file?");
        const std::string_view line = trim(strip_comment(raw));
        if (line.empty()) continue;
        const auto eq = line.find('=');
        if (eq == std::string_view::npos)
            throw InputError(
                where, fmt::format("expected 'key = value', got '{}'", quote_for_message(line)));
        const std::string key(trim(line.substr(0, eq)));
        const std::string value(trim(line.substr(eq + 1)));
        if (!valid_key(key))
            throw InputError(where, key, value, "is not a valid key name",
                             "letters, digits, '_' and '.', starting with a letter or '_'");
        if (value.empty()) throw InputError(where, key, value, "has no value");
        if (!tokenize(value)) throw InputError(where, key, value, "has an unterminated quote");
        if (const auto it = t.index_.find(key); it != t.index_.end())
            throw InputError(where, key, value,
                             fmt::format("is defined twice (first at line {})",
                                         t.entries_[it->second].where.line),
                             "one definition per key; override on the command line with key=value");
        t.index_.emplace(key, t.entries_.size());
        t.entries_.push_back({key, value, where});
    }
    return t;
}

std::string ParamTable::read_text_file(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec))
        throw InputError({path.string(), 0}, "file not found");
    if (std::filesystem::is_directory(path, ec))
        throw InputError({path.string(), 0}, "is a directory, not a file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError({path.string(), 0}, "cannot be opened for reading");
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

ParamTable ParamTable::from_file(const std::filesystem::path& path) {
    return from_text(read_text_file(path), path.string(), path.parent_path());
}

void ParamTable::add_override(std::string_view assignment) {
    const SourceLocation where{"<command line>", 0};
    const auto eq = assignment.find('=');
    if (eq == std::string_view::npos)
        throw InputError(
            where, fmt::format("expected key=value, got '{}'", quote_for_message(assignment)));
    const std::string key(trim(assignment.substr(0, eq)));
    const std::string value(trim(assignment.substr(eq + 1)));
    if (!valid_key(key))
        throw InputError(where, key, value, "is not a valid key name",
                         "letters, digits, '_' and '.', starting with a letter or '_'");
    if (value.empty()) throw InputError(where, key, value, "has no value");
    if (!tokenize(value)) throw InputError(where, key, value, "has an unterminated quote");
    overrides_.emplace_back(assignment);
    if (const auto it = index_.find(key); it != index_.end()) {
        entries_[it->second].value = value;
        entries_[it->second].where = where;
    } else {
        index_.emplace(key, entries_.size());
        entries_.push_back({key, value, where});
    }
}

Params ParamTable::root() { return Params(this, ""); }
Params ParamTable::scope(std::string_view prefix) { return Params(this, std::string(prefix) + "."); }

bool ParamTable::contains(std::string_view key) const { return index_.find(key) != index_.end(); }

const ParamEntry* ParamTable::find(std::string_view key) const {
    const auto it = index_.find(key);
    return it == index_.end() ? nullptr : &entries_[it->second];
}

void ParamTable::record(const std::string& key, const std::string& value,
                        const std::string& origin) {
    for (const auto& r : resolved_)
        if (r.key == key) return;
    resolved_.push_back({key, value, origin});
}

std::string ParamTable::closest_key(std::string_view key, bool among_queried) const {
    std::string best;
    std::size_t best_d = std::max<std::size_t>(2, key.size() / 4) + 1;
    auto consider = [&](const std::string& cand) {
        if (cand == key) return;
        // The edit distance is at least the difference in length: skip the quadratic work
        // for candidates that cannot win (a runaway key must not make an error message slow).
        const std::size_t gap =
            cand.size() > key.size() ? cand.size() - key.size() : key.size() - cand.size();
        if (gap >= best_d) return;
        const std::size_t d = edit_distance(key, cand);
        if (d < best_d) {
            best_d = d;
            best = cand;
        }
    };
    if (among_queried) {
        for (const auto& [k, _] : queried_) consider(k);
    } else {
        for (const auto& e : entries_)
            if (!e.used) consider(e.key);
    }
    return best;
}

std::vector<const ParamEntry*> ParamTable::unused_entries() const {
    std::vector<const ParamEntry*> out;
    for (const auto& e : entries_)
        if (!e.used) out.push_back(&e);
    return out;
}

void ParamTable::check_all_used(const UnusedKeyHint& hint) const {
    const auto unused = unused_entries();
    if (unused.empty()) return;
    const ParamEntry& first = *unused.front();
    std::string advice = hint ? hint(first) : std::string();
    if (advice.empty()) {
        const std::string near = closest_key(first.key, true);
        advice = near.empty() ? "no part of this scene reads it; remove it or check its spelling"
                              : fmt::format("did you mean '{}'?", near);
    }
    std::string problem = "was never read: " + advice;
    if (unused.size() > 1) {
        constexpr std::size_t kListed = 8;  // a long tail of unused keys would bury the message
        std::vector<std::string> rest;
        for (std::size_t i = 1; i < unused.size() && rest.size() < kListed; ++i)
            rest.push_back(quote_for_message(unused[i]->key, 60));
        if (unused.size() - 1 > kListed) rest.push_back("...");
        problem += fmt::format(" ({} more unused: {})", unused.size() - 1, join(rest));
    }
    throw InputError(first.where, first.key, first.value, problem,
                     "keys read by the top-level settings and by the effects in 'effects'");
}

// ---------------------------------------------------------------------------------------------
// Params

std::string Params::full_key(std::string_view key) const { return prefix_ + std::string(key); }

Params Params::scope(std::string_view sub) const {
    return Params(table_, prefix_ + std::string(sub) + ".");
}

bool Params::contains(std::string_view key) const { return table_->contains(full_key(key)); }

const ParamEntry* Params::lookup(std::string_view key) const {
    const std::string full = full_key(key);
    table_->note_query(full);
    const ParamEntry* e = table_->find(full);
    if (e) e->used = true;
    return e;
}

SourceLocation Params::location(std::string_view key) const {
    const ParamEntry* e = table_->find(full_key(key));
    return e ? e->where : SourceLocation{table_->file(), 0};
}

void Params::fail(std::string_view key, const std::string& problem,
                  const std::string& allowed) const {
    const std::string full = full_key(key);
    const ParamEntry* e = table_->find(full);
    throw InputError(e ? e->where : SourceLocation{table_->file(), 0}, full, e ? e->value : "",
                     problem, allowed);
}

void Params::fail_missing(const std::string& full, const std::string& expected) const {
    std::string problem = "is required but missing";
    const std::string near = table_->closest_key(full, false);
    if (!near.empty()) {
        const ParamEntry* e = table_->find(near);
        problem += fmt::format("; did you mean '{}' at {}?", near, e->where.to_string());
    }
    throw InputError({table_->file(), 0}, full, "", problem, expected);
}

template <class T>
T Params::get(std::string_view key, const Bounds& bounds) const {
    const std::string full = full_key(key);
    const ParamEntry* e = lookup(key);
    if (!e) fail_missing(full, ValueTraits<T>::expected(bounds));
    std::string problem;
    const auto toks = tokenize(e->value);
    const auto v = ValueTraits<T>::parse(*toks, bounds, problem);
    if (!v) throw InputError(e->where, full, e->value, problem, ValueTraits<T>::expected(bounds));
    table_->record(full, e->value, e->where.to_string());
    return *v;
}

template <class T>
T Params::get_or(std::string_view key, const T& fallback, const Bounds& bounds) const {
    if (!table_->contains(full_key(key))) {
        lookup(key);
        table_->record(full_key(key), ValueTraits<T>::show(fallback), "default");
        return fallback;
    }
    return get<T>(key, bounds);
}

#define EFDEM_PARAMS_INSTANTIATE(T)                                          \
    template T Params::get<T>(std::string_view, const Bounds&) const; \
    template T Params::get_or<T>(std::string_view, const T&, const Bounds&) const;
EFDEM_PARAMS_INSTANTIATE(double)
EFDEM_PARAMS_INSTANTIATE(int)
EFDEM_PARAMS_INSTANTIATE(long)
EFDEM_PARAMS_INSTANTIATE(std::uint64_t)
EFDEM_PARAMS_INSTANTIATE(bool)
EFDEM_PARAMS_INSTANTIATE(std::string)
EFDEM_PARAMS_INSTANTIATE(Vec3)
EFDEM_PARAMS_INSTANTIATE(std::vector<double>)
EFDEM_PARAMS_INSTANTIATE(std::vector<std::string>)
#undef EFDEM_PARAMS_INSTANTIATE

std::string Params::get_choice(std::string_view key, const std::vector<std::string>& allowed) const {
    const std::string word = get<std::string>(key);
    if (std::find(allowed.begin(), allowed.end(), word) == allowed.end())
        fail(key, "is not a known choice", join(allowed));
    return word;
}

std::string Params::get_or_choice(std::string_view key, const std::string& fallback,
                                  const std::vector<std::string>& allowed) const {
    if (!contains(key)) return get_or<std::string>(key, fallback);
    return get_choice(key, allowed);
}

std::filesystem::path Params::get_path(std::string_view key) const {
    std::filesystem::path p = get<std::string>(key);
    // Relative paths written in the scene resolve against the scene's folder; those given on the
    // command line resolve against the working directory, as a shell user expects.
    const bool from_scene = location(key).line > 0;
    if (p.is_relative() && from_scene && !table_->base_dir().empty()) p = table_->base_dir() / p;
    return p.lexically_normal();
}

std::filesystem::path Params::get_or_path(std::string_view key,
                                          const std::filesystem::path& fallback) const {
    if (!contains(key)) return get_or<std::string>(key, fallback.string());
    return get_path(key);
}

}  // namespace efdem
