#include "mpi_driver/run/listings.hpp"

#include <map>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "core/log.hpp"
#include "core/version.hpp"
#include "dem/effect_registry.hpp"

namespace efdem::mpi_driver {

namespace {
std::string effects_listing() {
    std::string out = "effects a scene can list (effects = name name ...):\n";
    for (const auto& e : dem::effect_registry().entries()) {
        out += fmt::format("  {:<16} {}\n", e.name, e.summary);
        // A key a run may change between steps: what continuation.parameter may name.
        for (const RunParameter& p : e.parameters)
            out += fmt::format("  {:<16} run parameter {}.{} {}: {}\n", "", e.name, p.key,
                               p.bounds.describe(), p.summary);
    }
    return out +
           "run parameters: keys a run may change between steps (mode = continuation follows "
           "one)\ndocumentation: docs/effects/<name>.md\n";
}
}  // namespace

bool print_listing(RunOptions::Action action) {
    switch (action) {
        case RunOptions::Action::help:
            log::output(RunOptions::usage());
            return true;
        case RunOptions::Action::version:
            log::output(
                fmt::format("efdem {} (git {}; {})\n", version(), git_hash(), build_info()));
            return true;
        case RunOptions::Action::list_effects:
            log::output(effects_listing());
            return true;
        default:
            return false;
    }
}

void print_keys(const ParamTable& table) {
    // The first sentence of each key's meaning in docs/scene_reference.md.
    static const std::map<std::string_view, std::string_view> meanings = {
#include "mpi_driver/run/key_meanings.inc"
    };
    std::string out = "key\tallowed\tdefault\tmeaning\n";
    for (const auto& d : table.declarations()) {
        const auto m = meanings.find(d.key);
        out +=
            fmt::format("{}\t{}\t{}\t{}\n", d.key, d.expected, d.required ? "required" : d.fallback,
                        m == meanings.end() ? std::string_view() : m->second);
    }
    log::output(out);
}

}  // namespace efdem::mpi_driver
