#pragma once
/// \file
/// The two kinds of *user-facing* failure (contracts, the third kind, are in contracts.hpp).
///
/// * InputError: something in the scene file, the command line or an input file is wrong. Always
///   checked. Every rank parses the same text, so every rank raises the same InputError; the driver
///   prints it once (root) and exits with kExitInputError. Nothing has been computed yet, so
///   nothing is lost.
/// * RuntimeFailure: a failure that only one rank sees while running (a non-finite position, an
///   I/O failure). The driver prints it with the rank and realization named and calls MPI_Abort,
///   so that no other rank waits forever in a collective.

#include <stdexcept>
#include <string>
#include <string_view>

namespace efdem {

/// Process exit codes used by the efdem executable and its scripts.
inline constexpr int kExitOk = 0;
inline constexpr int kExitInputError = 2;
inline constexpr int kExitRuntimeFailure = 3;
/// Stopped by a signal (SIGTERM, SIGINT, SIGUSR1) at a safe point, with a checkpoint written
/// there: the run can be continued with restart=FILE (a batch script can requeue on it).
inline constexpr int kExitInterrupted = 4;

/// How a piece of user input is quoted inside a message: control bytes and bytes that are not
/// printable ASCII or part of valid UTF-8 are shown as \xNN (a terminal never receives raw
/// escapes or NULs), and text longer than `max_chars` is cut, saying how long it was, so that a
/// runaway value cannot bury the message.
std::string quote_for_message(std::string_view text, std::size_t max_chars = 120);

/// Where a value came from: a file and a 1-based line, or the command line (line 0, file
/// "<command line>"), or nowhere (empty file: a required key that is missing).
struct SourceLocation {
    std::string file;
    int line = 0;
    std::string to_string() const;
};

/**
 * \brief A problem with the user's input, with enough context to fix it without reading code.
 *
 * The message always names where (file:line), which key, which value, what is wrong and what is
 * allowed. Example:
 * \code
 * throw InputError({"bed.cfg", 12}, "pair_contact.kn", "-5", "must be a stiffness",
 *                  "a finite real number > 0");
 * // what(): "bed.cfg:12: key 'pair_contact.kn' = '-5': must be a stiffness (allowed: a finite
 * //          real number > 0)"
 * \endcode
 */
class InputError : public std::runtime_error {
  public:
    InputError(SourceLocation where, std::string key, std::string value, std::string problem,
               std::string allowed = {});
    /// An input error that is not about a single key (a missing file, a syntax error).
    InputError(SourceLocation where, std::string problem);

    const SourceLocation& where() const { return where_; }
    const std::string& key() const { return key_; }
    const std::string& value() const { return value_; }
    const std::string& problem() const { return problem_; }
    const std::string& allowed() const { return allowed_; }

  private:
    SourceLocation where_;
    std::string key_, value_, problem_, allowed_;
};

/**
 * \brief A failure seen by one rank while running (numerical blow-up, I/O failure).
 *
 * Carries the realization index when one is known (-1 otherwise); the driver adds the rank.
 */
class RuntimeFailure : public std::runtime_error {
  public:
    explicit RuntimeFailure(const std::string& message, long realization = -1)
        : std::runtime_error(message), realization_(realization) {}
    long realization() const { return realization_; }

  private:
    long realization_;
};

}  // namespace efdem
