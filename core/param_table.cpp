/// \file
/// The lookup side of the scene reader (see param_table.hpp): the table of entries, overrides,
/// scoped typed reads, defaults and the check that every key was read. The text itself is lexed
/// by core/scene_lexer.hpp and values are parsed by core/param_value.hpp.
#include "core/param_table.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "core/file_kind.hpp"
#include "core/param_value.hpp"
#include "core/scene_lexer.hpp"

namespace efdem {

namespace {

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

std::string comma_list(const std::vector<std::string>& words) {
    return fmt::format("{}", fmt::join(words, ", "));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ParamTable

ParamTable ParamTable::from_text(std::string_view text, std::string file,
                                 std::filesystem::path base_dir) {
    ParamTable t;
    t.text_ = std::string(text);
    t.file_ = std::move(file);
    t.base_dir_ = std::move(base_dir);
    for (SceneAssignment& a : lex_scene(text, t.file_)) {
        t.index_.emplace(a.key, t.entries_.size());
        t.entries_.push_back({std::move(a.key), std::move(a.value), std::move(a.where)});
    }
    return t;
}

std::string ParamTable::read_text_file(const std::filesystem::path& path) {
    // Regular files only: a FIFO would block until someone writes to it, a device such as
    // /dev/zero would be read until memory runs out.
    if (const std::string what = not_a_regular_file(path); !what.empty())
        throw InputError({path.string(), 0},
                         what == "file not found" ? what : what + "; a scene is a regular file");
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    if (!ec && size > kMaxSceneBytes)
        throw InputError({path.string(), 0},
                         fmt::format("is {} bytes long; a scene is a text file of at most {} "
                                     "bytes (particle data are read from the files it names)",
                                     size, kMaxSceneBytes));
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
    SceneAssignment a =
        parse_assignment(assignment, {"<command line>", 0}, AssignmentForm::command_line);
    overrides_.emplace_back(assignment);
    if (const auto it = index_.find(a.key); it != index_.end()) {
        entries_[it->second].value = std::move(a.value);
        entries_[it->second].where = std::move(a.where);
    } else {
        index_.emplace(a.key, entries_.size());
        entries_.push_back({std::move(a.key), std::move(a.value), std::move(a.where)});
    }
}

Params ParamTable::root() {
    return Params(this, "");
}
Params ParamTable::scope(std::string_view prefix) {
    return Params(this, std::string(prefix) + ".");
}

bool ParamTable::contains(std::string_view key) const {
    return index_.find(key) != index_.end();
}

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

void ParamTable::declare(const std::string& key, const std::string& expected,
                         const std::string* fallback) const {
    auto it = std::find_if(declarations_.begin(), declarations_.end(),
                           [&](const KeyDeclaration& d) { return d.key == key; });
    if (it == declarations_.end()) {
        declarations_.push_back(
            {key, expected, fallback ? *fallback : std::string(), fallback == nullptr});
        return;
    }
    if (!expected.empty()) it->expected = expected;
    if (fallback) {
        it->fallback = *fallback;
        it->required = false;
    }
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
        problem += fmt::format(" ({} more unused: {})", unused.size() - 1, comma_list(rest));
    }
    throw InputError(first.where, first.key, first.value, problem,
                     "keys read by the top-level settings and by the effects in 'effects'");
}

// ---------------------------------------------------------------------------------------------
// Params

std::string Params::full_key(std::string_view key) const {
    return prefix_ + std::string(key);
}

Params Params::scope(std::string_view sub) const {
    return Params(table_, prefix_ + std::string(sub) + ".");
}

bool Params::contains(std::string_view key) const {
    return table_->contains(full_key(key));
}

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
    table_->declare(full, param_value_expected<T>(bounds), nullptr);
    const ParamEntry* e = lookup(key);
    if (!e) fail_missing(full, param_value_expected<T>(bounds));
    std::string problem;
    const auto toks = split_value(e->value);  // every entry passed parse_assignment: no nullopt
    const auto v = parse_param_value<T>(*toks, bounds, problem);
    if (!v) throw InputError(e->where, full, e->value, problem, param_value_expected<T>(bounds));
    table_->record(full, e->value, e->where.to_string());
    return *v;
}

template <class T>
T Params::get_or(std::string_view key, const T& fallback, const Bounds& bounds) const {
    const std::string shown = show_param_value<T>(fallback);
    table_->declare(full_key(key), param_value_expected<T>(bounds), &shown);
    if (!table_->contains(full_key(key))) {
        lookup(key);
        table_->record(full_key(key), show_param_value<T>(fallback), "default");
        return fallback;
    }
    return get<T>(key, bounds);
}

#define EFDEM_PARAMS_INSTANTIATE(T)                                   \
    template T Params::get<T>(std::string_view, const Bounds&) const; \
    template T Params::get_or<T>(std::string_view, const T&, const Bounds&) const;
EFDEM_PARAM_VALUE_TYPES(EFDEM_PARAMS_INSTANTIATE)
#undef EFDEM_PARAMS_INSTANTIATE

std::string Params::get_choice(std::string_view key,
                               const std::vector<std::string>& allowed) const {
    const std::string word = get<std::string>(key);
    table_->declare(full_key(key), "one of: " + comma_list(allowed), nullptr);
    if (std::find(allowed.begin(), allowed.end(), word) == allowed.end())
        fail(key, "is not a known choice", comma_list(allowed));
    return word;
}

std::string Params::get_or_choice(std::string_view key, const std::string& fallback,
                                  const std::vector<std::string>& allowed) const {
    table_->declare(full_key(key), "",
                    &fallback);  // the default, whether or not the scene sets the key
    const std::string word =
        contains(key) ? get_choice(key, allowed) : get_or<std::string>(key, fallback);
    table_->declare(full_key(key), "one of: " + comma_list(allowed),
                    nullptr);  // after get_or's "one word"
    return word;
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
    const std::string shown = fallback.string();
    table_->declare(full_key(key), "", &shown);
    if (!contains(key)) return get_or<std::string>(key, fallback.string());
    return get_path(key);
}

}  // namespace efdem
