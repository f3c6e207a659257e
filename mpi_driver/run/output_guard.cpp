#include "mpi_driver/run/output_guard.hpp"

#include <unistd.h>
#include <algorithm>
#include <cctype>
#include <system_error>

#include <fmt/format.h>

#include "core/error.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"

namespace efdem::mpi_driver {

namespace {
bool digits(std::string_view s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c));
    });
}

/// `name` (without a trailing .tmp) is a per-realization file of `prefix`: PREFIX_rNNNN.pvd,
/// PREFIX_rNNNN_NNNNNN.vtp or PREFIX_rNNNN_thermo.csv, with _contNNNNNNNN after rNNNN in a
/// restarted run's files.
bool is_realization_file(std::string_view name, const std::string& prefix) {
    const std::string head = prefix + "_r";
    if (name.substr(0, head.size()) != head) return false;
    std::string_view rest = name.substr(head.size());
    const std::size_t end = rest.find_first_not_of("0123456789");
    if (end == 0 || end == std::string_view::npos) return false;
    rest = rest.substr(end);
    if (rest.substr(0, 5) == "_cont" && rest.size() > 13 && digits(rest.substr(5, 8)))
        rest = rest.substr(13);
    if (rest == ".pvd" || rest == "_thermo.csv") return true;
    return rest.size() > 5 && rest[0] == '_' && rest.substr(rest.size() - 4) == ".vtp" &&
           digits(rest.substr(1, rest.size() - 5));
}

bool is_run_file(std::string_view name, const std::string& prefix) {
    return name == prefix + ".h5" || name == prefix + ".h5.reserve" ||
           name == prefix + "_mean_icdf.csv" || name == prefix + "_cpi_steps.csv" ||
           name == prefix + "_csv_meta.json";
}

void collect(const std::filesystem::path& dir, const std::string& prefix, bool checkpoints,
             std::vector<std::filesystem::path>& out) {
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) return;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
        std::string name = entry.path().filename().string();
        if (name.ends_with(".tmp")) name.resize(name.size() - 4);
        const bool ours = checkpoints
                              ? is_checkpoint_file_name(name, prefix)
                              : is_run_file(name, prefix) || is_realization_file(name, prefix);
        if (ours) out.push_back(entry.path());
    }
}
}  // namespace

std::vector<std::filesystem::path> existing_run_files(const RunSettings& s) {
    std::vector<std::filesystem::path> out;
    collect(s.output.directory, s.output.prefix, false, out);
    collect(s.checkpoint.directory, s.output.prefix, true, out);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

std::string unwritable_directory(const std::filesystem::path& directory) {
    std::error_code ec;
    std::filesystem::path p = directory.empty() ? std::filesystem::path(".") : directory;
    // The directory itself, or the nearest parent that exists (where it would be created).
    while (!std::filesystem::exists(p, ec)) {
        const auto parent = p.has_parent_path() && p.parent_path() != p
                                ? p.parent_path()
                                : std::filesystem::path(".");
        if (parent == p) break;
        p = parent;
    }
    if (!std::filesystem::is_directory(p, ec))
        return fmt::format("'{}' exists and is not a directory", p.string());
    if (::access(p.c_str(), W_OK | X_OK) != 0)
        return p == directory ? std::string("it is not writable (permissions)")
                              : fmt::format("it does not exist and its parent '{}' is not writable",
                                            p.string());
    return {};
}

void check_output_is_free(const Params& root, const RunSettings& s, bool restarting) {
    const Params output = root.scope("output");
    if (const std::string why = unwritable_directory(s.output.directory); !why.empty())
        output.fail("directory", fmt::format("cannot be written to: {}", why),
                    "a directory this user can write");
    if (s.checkpoint.directory != s.output.directory)
        if (const std::string why = unwritable_directory(s.checkpoint.directory); !why.empty())
            root.scope("checkpoint")
                .fail("directory", fmt::format("cannot be written to: {}", why),
                      "a directory this user can write");
    if (restarting || s.output.overwrite) return;
    const auto files = existing_run_files(s);
    if (files.empty()) return;
    std::string more;
    if (files.size() > 1) more = fmt::format(" and {} more file(s) of that run", files.size() - 1);
    output.fail("prefix",
                fmt::format("names an earlier run: {} exists{} (nothing was overwritten)",
                            files.front().string(), more),
                "another output.prefix or output.directory; output.overwrite = true to delete that "
                "run's files "
                "and replace it; or continue it with restart=CHECKPOINT");
}

std::vector<std::filesystem::path> remove_earlier_run(const RunSettings& s) {
    const auto files = existing_run_files(s);
    for (const auto& f : files) {
        std::error_code ec;
        std::filesystem::remove(f, ec);
        if (ec)
            throw RuntimeFailure(
                fmt::format("output.overwrite: cannot delete {}: {}", f.string(), ec.message()));
    }
    return files;
}

}  // namespace efdem::mpi_driver
