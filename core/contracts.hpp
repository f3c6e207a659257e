#pragma once
/// \file
/// Contracts: checks of *programmer* errors (a violated precondition or postcondition inside
/// efdem), kept apart from input errors (core/error.hpp), which are always checked.
///
/// Contracts are active in debug builds (no NDEBUG) and when EFDEM_ENFORCE_CONTRACTS is defined;
/// they compile to nothing otherwise, so they may sit in hot loops. A violated contract prints the
/// condition and its source location and aborts: it is a bug in efdem, not something a user did.

namespace efdem::detail {
[[noreturn]] void contract_violation(const char* kind, const char* condition, const char* file,
                                     int line) noexcept;
}

#if !defined(NDEBUG) || defined(EFDEM_ENFORCE_CONTRACTS)
#define EFDEM_CONTRACTS_ACTIVE 1
#define EFDEM_CONTRACT_CHECK_(kind, ...)                                                 \
    do {                                                                                 \
        if (!(__VA_ARGS__))                                                              \
            ::efdem::detail::contract_violation(kind, #__VA_ARGS__, __FILE__, __LINE__); \
    } while (false)
#else
#define EFDEM_CONTRACTS_ACTIVE 0
#define EFDEM_CONTRACT_CHECK_(kind, ...) \
    do {                                 \
    } while (false)
#endif

/// Precondition of a function (what the caller must guarantee).
#define EFDEM_EXPECTS(...) EFDEM_CONTRACT_CHECK_("precondition", __VA_ARGS__)
/// Postcondition of a function (what it guarantees on return).
#define EFDEM_ENSURES(...) EFDEM_CONTRACT_CHECK_("postcondition", __VA_ARGS__)
/// Internal invariant.
#define EFDEM_ASSERT(...) EFDEM_CONTRACT_CHECK_("invariant", __VA_ARGS__)
