#include "mpi_driver/checkpoint/restart_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <sstream>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"

namespace efdem::mpi_driver {

namespace {
std::map<std::string, std::string> parse_lines(const std::string& text) {
    std::map<std::string, std::string> out;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        const auto eq = line.find(" = ");
        if (eq != std::string::npos) out[line.substr(0, eq)] = line.substr(eq + 3);
    }
    return out;
}

/// Keys added after checkpoints were first written, with the value that does what a run did
/// before the key existed: a checkpoint that does not list the key was written with that value.
/// nullptr: any value (a key that only acts with another added key at a value other than its
/// old one).
// clang-format off
constexpr std::pair<const char*, const char*> kAddedKeys[] = {
    {"cpi.slope", "burst"},  // cpi.slope = pooled (issue 33)
    {"cpi.pool", "4"},  // read with cpi.slope, cpi.curvature or cpi.noisy_curvature = pooled
    {"cpi.slope_fit", "least_squares"},  // increment: the window's increment (issue 34)
    {"cpi.curvature", "none"},  // pooled: the bursts' curvature added to each jump (issue 34)
    {"cpi.healing_auto", "false"},
    {"cpi.window_auto", "false"},
    {"cpi.window_max", nullptr},  // read only with cpi.window_auto
    {"cpi.noisy_curvature", "counted"},
    {"cpi.at_rest", "lift"},  // hold: realizations at rest are not lifted (issue 34)
    {"cpi.finish", "duration"},  // steady: end at the end state (issue 34)
    {"cpi.relabel", "any"},      // moving: relabel moving particles first (issue 34)
    {"cpi.hand_off", "none"},    // steady: the end state goes to the steady solver (issue 34)
    {"gas_drag.polydisperse", "none"},  // van_der_hoef: spheres of several sizes (issue 37)
    {"cpi.lift_by", "colours"},         // positions: exchange particles (issue 37)
    {"cpi.lift_height_band", "0.25"},   // positions: the relaxation's band (issue 37)
    {"cpi.lift_resolution", "0.1"},     // positions, large observed: rank windows (issue 37)
    {"cpi.lift_error", "ignored"},      // counted: in the jump's error (issue 37)
    {"cpi.relabel_nodes", "random"},    // matched: node-aware colour lift (issue 34)
    {"cpi.relabel_velocity", "kept"},   // species: relabelled take the species' drift (issue 34)
};
// clang-format on

/// A direct run simulates nothing the cpi block says (the block is read and checked in every
/// mode; the warm-up, bursts, projection and lift are the cpi and steady drivers' alone), so in
/// a direct run and its checkpoint every cpi.* key may differ or be missing. Above all a cpi key
/// added since the checkpoint (kAddedKeys) at a default other than its old behaviour must not
/// stop a direct run from continuing (cpi.relabel_nodes = matched refused a 450-unit direct run).
bool ignored_in(const std::map<std::string, std::string>& now, const std::string& key) {
    const auto mode = now.find("mode");
    return mode != now.end() && mode->second == "direct" && key.rfind("cpi.", 0) == 0;
}

bool as_before_the_key(const std::string& key, const std::string& value) {
    for (const auto& [k, v] : kAddedKeys)
        if (key == k) return v == nullptr || value == v;
    return false;
}

/// cpi.jump_until in a parameter list: its value, infinity when the list does not set it.
double jump_until_in(const std::map<std::string, std::string>& params) {
    const auto it = params.find("cpi.jump_until");
    return it == params.end() ? std::numeric_limits<double>::infinity()
                              : std::strtod(it->second.c_str(), nullptr);
}

/// cpi.jump_until may change on a restart as long as what the run did so far keeps to it: no
/// jump of the run ended later than the new value (the jumps so far ended by the old value and
/// by the checkpoint's time, `elapsed` after the run's start). True when it may (or did not
/// change); throws InputError when the new value would be broken by the jumps already made;
/// false when the checkpoint's time is not known (then it is physics, as other keys).
bool jump_until_may_change(const SourceLocation& where,
                           const std::map<std::string, std::string>& then,
                           const std::map<std::string, std::string>& now, double elapsed) {
    const double before = jump_until_in(then), after = jump_until_in(now);
    if (before == after) return true;
    if (!std::isfinite(elapsed)) return false;
    const double kept = std::min(before, elapsed);
    if (after >= kept - 1e-9 * std::max(1.0, kept)) return true;
    throw InputError(
        where,
        fmt::format("cpi.jump_until = {:g}, but the run's jumps went on until {:g} time "
                    "units after its start (the checkpoint is {:g} units in{}): a restart may "
                    "end the jumps from the checkpoint on, not before it. Give "
                    "cpi.jump_until >= {:g}",
                    after, kept, elapsed,
                    std::isfinite(before) ? fmt::format(", cpi.jump_until = {:g}", before)
                                          : std::string(", jumps to the end"),
                    kept));
}

/// The first `most` of `items` joined with "; ", and how many more there are.
std::string joined(const std::vector<std::string>& items, std::size_t most) {
    std::string list;
    for (std::size_t k = 0; k < items.size() && k < most; ++k) list += (k ? "; " : "") + items[k];
    if (items.size() > most) list += fmt::format("; and {} more", items.size() - most);
    return list;
}

/// What a checkpoint that does not list `key` was written with ("" when the key is not one of
/// kAddedKeys or any value does).
std::string value_before_the_key(const std::string& key) {
    for (const auto& [k, v] : kAddedKeys)
        if (key == k && v != nullptr) return v;
    return {};
}
}  // namespace

std::string parameter_lines(const ParamTable& table) {
    std::string out;
    for (const auto& r : table.resolved()) out += fmt::format("{} = {}\n", r.key, r.value);
    return out;
}

bool may_change_on_restart(const std::string& key) {
    for (const char* scope : {"output.", "checkpoint.", "restart.", "debug.", "watchdog."})
        if (key.rfind(scope, 0) == 0) return true;
    // ensemble.at_rest: pausing a bed at rest changes its state by floating-point drift alone.
    // bed.write, bed.read*: where the initial beds were kept or came from; a restart neither
    // writes nor reads them (the checkpoint holds every particle state).
    // cpi.finish: like run.duration, where the run ends, not what it simulates (a run that ended
    // at its end state can go on to check it; the drift test's pool starts empty when the
    // checkpoint has none).
    return key == "run.duration" || key == "cpi.finish" ||
           key == "ensemble.realizations_per_rank" || key == "ensemble.at_rest" ||
           key == "bed.write" || key == "bed.read" || key.rfind("bed.read.", 0) == 0;
}

bool shapes_the_run_file(const std::string& key) {
    return key.rfind("observe.", 0) == 0;
}

std::string check_restart(const std::filesystem::path& path, const CheckpointHeader& h,
                          const std::string& parameters_now, long realizations_now,
                          bool allow_physics_change, double time_at_checkpoint) {
    const SourceLocation where{path.string(), 0};
    if (h.realizations != realizations_now)
        throw InputError(
            where, fmt::format("checkpoint holds {} realizations but this run has {} (ranks x "
                               "ensemble.realizations_per_rank); restart with the same number",
                               h.realizations, realizations_now));
    const auto then = parse_lines(h.parameters), now = parse_lines(parameters_now);
    // Not physics: a run of one mode has no state (integrator, run-file groups) to continue one
    // of another, so not even restart.allow_physics_change allows it.
    const auto mode_then = then.find("mode"), mode_now = now.find("mode");
    if (mode_then != then.end() && mode_now != now.end() && mode_then->second != mode_now->second)
        throw InputError(
            where, fmt::format("checkpoint was written by a mode = {} run and this run has mode = "
                               "{}; a restart continues the run that wrote the checkpoint, in its "
                               "mode (restart with mode = {})",
                               mode_then->second, mode_now->second, mode_then->second));
    // Not physics either: the run file's grid. Its rows so far were sampled on it.
    std::vector<std::string> grid;
    for (const auto& [key, value] : now)
        if (shapes_the_run_file(key))
            if (const auto it = then.find(key); it != then.end() && it->second != value)
                grid.push_back(fmt::format("{} = {} (checkpoint: {})", key, value, it->second));
    if (!grid.empty()) {
        throw InputError(
            where, fmt::format("a restart continues the run file, whose samples were made with "
                               "the checkpoint's observe.* values, and this scene changes them: "
                               "{}. Restart with the checkpoint's values (not even "
                               "restart.allow_physics_change changes them)",
                               joined(grid, grid.size())));
    }
    // Time units the run had simulated at the checkpoint (NaN: not known).
    const double elapsed = time_at_checkpoint - h.driver.t_origin;
    const auto duration = now.find("run.duration");
    if (std::isfinite(elapsed) && duration != now.end()) {
        const double d = std::strtod(duration->second.c_str(), nullptr);
        if (d <= elapsed + 1e-9 * std::max(1.0, std::abs(d)))
            throw InputError(
                where, fmt::format("run.duration = {}, but the run had already simulated {:.6g} "
                                   "time units at this checkpoint (t = {:.6g}, from t = {:.6g}): "
                                   "a restart runs on until t = {:.6g} + run.duration, so it would "
                                   "have nothing to run (and would set the run's files back to "
                                   "the checkpoint). Give a run.duration longer than {:.6g} to "
                                   "continue the run",
                                   duration->second, elapsed, time_at_checkpoint, h.driver.t_origin,
                                   h.driver.t_origin, elapsed));
    }
    // cpi.jump_until: where the jumps end (a run that jumped so far may go on directly from its
    // checkpoint), within what the run did so far.
    const bool jumps_end_may_change = jump_until_may_change(where, then, now, elapsed);
    const auto unchecked = [&](const std::string& key) {
        return may_change_on_restart(key) || ignored_in(now, key) ||
               (key == "cpi.jump_until" && jumps_end_may_change);
    };
    std::vector<std::string> changes;
    for (const auto& [key, value] : now) {
        if (unchecked(key)) continue;
        const auto it = then.find(key);
        if (it == then.end()) {
            if (as_before_the_key(key, value)) continue;
            const std::string before = value_before_the_key(key);
            changes.push_back(
                before.empty()
                    ? fmt::format("{} = {} (not in the checkpoint)", key, value)
                    : fmt::format("{} = {} (not in the checkpoint, whose run did {} = {})", key,
                                  value, key, before));
        } else if (it->second != value) {
            changes.push_back(fmt::format("{} = {} (checkpoint: {})", key, value, it->second));
        }
    }
    for (const auto& [key, value] : then)
        if (!unchecked(key) && !now.contains(key))
            changes.push_back(fmt::format("{} missing (checkpoint: {})", key, value));
    if (changes.empty()) return {};
    const std::string list = joined(changes, 8);
    if (!allow_physics_change)
        throw InputError(
            where, fmt::format("checkpoint was written by a scene with different physics: {}. "
                               "Restart with the checkpoint's scene, or accept the change "
                               "with restart.allow_physics_change=true",
                               list));
    return fmt::format(
        "restart from {} with changed physics (restart.allow_physics_change = true): {}",
        path.string(), list);
}

}  // namespace efdem::mpi_driver
