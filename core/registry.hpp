#pragma once
/// \file
/// Registry: a checked-in table of named factories (after LAMMPS' gran_sub_mod_register.cpp).
///
/// One row per plug-in: its name, a factory, a one-line summary and the keys a run may change.
/// No macros, no self-registration: the table is an ordinary array that a reader can find and
/// read (a row may call a function for its run parameters, so the table is made at start-up).

#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/bounds.hpp"

namespace efdem {

/// A key of a plug-in that a run may change while it goes on (the parameter a continuation
/// follows): its name in the plug-in's scope, the bounds the scene reads it with (one owner:
/// the plug-in reads the key with these bounds too) and a one-line summary.
struct RunParameter {
    std::string_view key;  ///< in the plug-in's scope: "superficial_velocity"
    Bounds bounds;
    std::string_view summary;
};

/**
 * \brief A name -> factory table for plug-ins of base type `Product`; a row may also list the
 * plug-in's RunParameters (keys a run may change between steps).
 * \tparam Product the interface the factories return
 * \tparam Args    the arguments every factory takes
 *
 * \code
 * const Registry<Effect, Params>::Entry kEffects[] = {
 *     {"gravity", &make<Gravity>, "uniform body force m g"},
 * };
 * Registry<Effect, Params> registry(kEffects);
 * if (const auto* e = registry.find("gravity")) auto effect = e->make(params);
 * \endcode
 */
template <class Product, class... Args>
class Registry {
  public:
    using Factory = std::unique_ptr<Product> (*)(Args...);
    struct Entry {
        std::string_view name;
        Factory make;
        std::string_view summary;
        std::span<const RunParameter> parameters = {};  ///< keys a run may change
    };

    constexpr explicit Registry(std::span<const Entry> entries) : entries_(entries) {}

    /// The entry called `name`, or nullptr.
    const Entry* find(std::string_view name) const {
        for (const auto& e : entries_)
            if (e.name == name) return &e;
        return nullptr;
    }
    std::vector<std::string> names() const {
        std::vector<std::string> out;
        for (const auto& e : entries_) out.emplace_back(e.name);
        return out;
    }
    /// "a, b, c": for "known names are ..." messages.
    std::string names_joined() const {
        std::string out;
        for (const auto& e : entries_) {
            if (!out.empty()) out += ", ";
            out += e.name;
        }
        return out;
    }
    std::span<const Entry> entries() const { return entries_; }

  private:
    std::span<const Entry> entries_;
};

/// The factory used in registry tables: constructs `T` from the registry's arguments.
template <class Product, class T, class... Args>
std::unique_ptr<Product> make_as(Args... args) {
    return std::make_unique<T>(args...);
}

}  // namespace efdem
