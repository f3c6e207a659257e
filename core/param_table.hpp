#pragma once
/// \file
/// ParamTable: the strict scene-file reader (after AMReX ParmParse), and Params, a scoped view.
///
/// Format: one `key = value` per line; `#` starts a comment; keys are dotted scopes
/// (`pair_contact.kn`); a value is one or more whitespace-separated tokens (a vector), and a token
/// may be double-quoted to hold spaces. Command-line `key=value` overrides come last and win.
///
/// Rules that make "simulate only what the scene asks for" safe:
/// * `get` (required) fails with the key and the expected type if the key is missing;
///   `get_or` (optional) records the default it used, so a run's log is a complete record.
/// * Every value is parsed strictly (no trailing garbage, finite numbers, bounds checked).
/// * After set-up, `check_all_used()` fails on the first key nothing read, naming it and
///   suggesting what was probably meant.
/// * A key defined twice in the file is an error (overrides are the only way to redefine).
///
/// The reader's jobs, a file pair each: core/scene_lexer.hpp (text to `key = value` with file:line,
/// and the one syntax check that scene lines and command-line overrides share),
/// core/param_value.hpp (value tokens to typed values, Bounds checked) and this file (lookup).

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/bounds.hpp"
#include "core/error.hpp"
#include "core/vec3.hpp"

namespace efdem {

class Params;

/// One `key = value` definition and whether anything has read it.
struct ParamEntry {
    std::string key;
    std::string value;  ///< raw value text, comment stripped, trimmed
    SourceLocation where;
    mutable bool used = false;
};

/// A parameter as the run actually used it: from the input or a default.
struct ResolvedParam {
    std::string key;
    std::string value;
    std::string origin;  ///< "scene.cfg:12", "<command line>" or "default"
};

/// A key as the code declares it when it reads it: what it accepts and its default. Collected
/// for every key queried (present in the scene or not), so that `efdem --list-keys` prints the
/// keys a scene's set-up reads, and a test checks docs/scene_reference.md against them.
struct KeyDeclaration {
    std::string key;
    std::string expected;  ///< "a real number > 0", "one of: direct, cpi", ...
    std::string fallback;  ///< the default as text; empty when required
    bool required = true;
};

/// Returns a hint sentence for an unused key ("is 'gas_drag' listed in 'effects'?") or "".
using UnusedKeyHint = std::function<std::string(const ParamEntry&)>;

class ParamTable {
  public:
    /// Parses scene text. `file` names the text in messages; relative paths in the scene resolve
    /// against `base_dir`. Throws InputError on a syntax error or a duplicated key.
    static ParamTable from_text(std::string_view text, std::string file,
                                std::filesystem::path base_dir = {});
    /// Reads and parses a file (InputError if it cannot be read).
    static ParamTable from_file(const std::filesystem::path& path);
    /// Reads a whole file into a string; InputError naming the file if it cannot be read, is
    /// not a regular file (saying what it is) or is longer than kMaxSceneBytes.
    static std::string read_text_file(const std::filesystem::path& path);
    /// A scene is a few kB of text; 16 MiB leaves room for any hand-made one and stops a
    /// mistaken data file before it fills memory.
    static constexpr std::uintmax_t kMaxSceneBytes = 16u << 20;

    /// Applies a command-line override "key=value"; it replaces any definition in the file.
    void add_override(std::string_view assignment);

    /// A view of all keys, or of the keys under `prefix.` (e.g. scope("gas_drag")).
    Params root();
    Params scope(std::string_view prefix);

    bool contains(std::string_view key) const;
    const ParamEntry* find(std::string_view key) const;

    /// Throws InputError for the first key (in file order) that nothing read. The message names
    /// the key, its location and value, the hint (if any) or the closest key that was read.
    void check_all_used(const UnusedKeyHint& hint = {}) const;
    std::vector<const ParamEntry*> unused_entries() const;

    /// The scene text as read (for provenance), the file name, the overrides as given.
    const std::string& text() const { return text_; }
    const std::string& file() const { return file_; }
    const std::filesystem::path& base_dir() const { return base_dir_; }
    const std::vector<std::string>& overrides() const { return overrides_; }
    /// Every parameter read so far with its value and origin, in the order first read.
    const std::vector<ResolvedParam>& resolved() const { return resolved_; }
    /// Every key queried so far, in the order first queried.
    const std::vector<KeyDeclaration>& declarations() const { return declarations_; }
    /// All entries in file order (overrides last).
    const std::vector<ParamEntry>& entries() const { return entries_; }

  private:
    friend class Params;
    ParamTable() = default;
    void record(const std::string& key, const std::string& value, const std::string& origin);
    void note_query(const std::string& key) const { queried_.emplace(key, true); }
    /// Records what `key` accepts; a later call refines it (a choice list, a default).
    void declare(const std::string& key, const std::string& expected,
                 const std::string* fallback) const;
    std::string closest_key(std::string_view key, bool among_queried) const;

    std::string text_;
    std::string file_;
    std::filesystem::path base_dir_;
    std::vector<std::string> overrides_;
    std::vector<ParamEntry> entries_;
    std::map<std::string, std::size_t, std::less<>> index_;
    std::vector<ResolvedParam> resolved_;
    mutable std::map<std::string, bool, std::less<>> queried_;
    mutable std::vector<KeyDeclaration> declarations_;
};

/**
 * \brief A scoped, typed view of a ParamTable: what effects and components read.
 *
 * Supported types: double, int, long, std::uint64_t, bool, std::string, Vec3,
 * std::vector<double>, std::vector<std::string>. Numbers may be bounded:
 * \code
 * Params p = table.scope("pair_contact");
 * double kn = p.get<double>("kn", Bounds::positive());
 * double e  = p.get_or<double>("restitution", 0.9, Bounds::open_closed(0, 1));
 * std::string law = p.get_choice("normal", {"hooke", "hertz"});
 * \endcode
 */
class Params {
  public:
    Params(ParamTable* table, std::string prefix) : table_(table), prefix_(std::move(prefix)) {}

    template <class T>
    T get(std::string_view key, const Bounds& bounds = {}) const;
    template <class T>
    T get_or(std::string_view key, const T& fallback, const Bounds& bounds = {}) const;

    /// A word from a fixed list; the error lists the allowed words.
    std::string get_choice(std::string_view key, const std::vector<std::string>& allowed) const;
    std::string get_or_choice(std::string_view key, const std::string& fallback,
                              const std::vector<std::string>& allowed) const;
    /// A path; relative paths resolve against the scene file's folder.
    std::filesystem::path get_path(std::string_view key) const;
    std::filesystem::path get_or_path(std::string_view key,
                                      const std::filesystem::path& fallback) const;

    /// True if the key is defined (does not count as reading it).
    bool contains(std::string_view key) const;
    /// The full dotted key name of `key` in this scope.
    std::string full_key(std::string_view key) const;
    Params scope(std::string_view sub) const;
    SourceLocation location(std::string_view key) const;
    /// Raises an InputError about `key` at its location, quoting its value.
    [[noreturn]] void fail(std::string_view key, const std::string& problem,
                           const std::string& allowed = {}) const;
    ParamTable& table() const { return *table_; }

  private:
    const ParamEntry* lookup(std::string_view key) const;
    [[noreturn]] void fail_missing(const std::string& full, const std::string& expected) const;

    ParamTable* table_;
    std::string prefix_;
};

}  // namespace efdem
