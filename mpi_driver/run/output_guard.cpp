#include "mpi_driver/run/output_guard.hpp"

#include <unistd.h>
#include <algorithm>
#include <cctype>
#include <exception>
#include <optional>
#include <system_error>

#include <fmt/format.h>

#include "core/error.hpp"
#include "dem/io/lammps_data.hpp"
#include "mpi_driver/checkpoint_data/checkpoint_format.hpp"
#if EFDEM_HAVE_HDF5
#include "mpi_driver/checkpoint/checkpoint_reader.hpp"
#include "mpi_driver/output/h5_file.hpp"
#include "mpi_driver/output/run_identity.hpp"
#endif

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
           name == prefix + "_log.txt" || name == prefix + "_mean_icdf.csv" ||
           name == prefix + "_cpi_steps.csv" || name == prefix + "_csv_meta.json";
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

void check_output_is_writable(const Params& root, const RunSettings& s) {
    const Params output = root.scope("output");
    if (const std::string why = unwritable_directory(s.output.directory); !why.empty())
        output.fail("directory", fmt::format("cannot be written to: {}", why),
                    "a directory this user can write");
    if (s.checkpoint.directory != s.output.directory)
        if (const std::string why = unwritable_directory(s.checkpoint.directory); !why.empty())
            root.scope("checkpoint")
                .fail("directory", fmt::format("cannot be written to: {}", why),
                      "a directory this user can write");
}

void check_output_is_free(const Params& root, const RunSettings& s, bool restarting) {
    const Params output = root.scope("output");
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

void check_bed_write_is_free(const Params& root, const RunSettings& s, long realizations,
                             bool restarting) {
    if (restarting || s.output.overwrite || s.output.bed_write.empty()) return;
    std::error_code ec;
    for (long r = 0; r < realizations; ++r)
        if (const auto file = dem::realization_file(s.output.bed_write, r);
            std::filesystem::exists(file, ec))
            root.scope("bed").fail(
                "write",
                fmt::format("would write over {}, which exists (nothing was overwritten)",
                            file.string()),
                "a name no earlier bed file has; bed.read = the same name to start from those "
                "beds instead; or output.overwrite = true to replace them");
}

#if EFDEM_HAVE_HDF5
namespace {
/// The identity of the run whose run file a checkpoint stores (empty optional: it stores none,
/// or the file cannot be read).
std::optional<RunIdentity> checkpoint_run(const CheckpointHeader& header,
                                          const std::filesystem::path& path) {
    for (const auto& o : header.outputs)
        if (o.name == ".h5") {
            try {
                return read_run_identity(
                    H5File::open_image(o.bytes, path.string() + " (its copy of the run file)"));
            } catch (const RuntimeFailure&) {
                return std::nullopt;
            }
        }
    return std::nullopt;
}

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
    std::error_code ec;
    return std::filesystem::equivalent(a, b, ec);
}
}  // namespace

void check_restart_target(const Params& root, const RunSettings& s,
                          const std::filesystem::path& checkpoint, const CheckpointHeader& header) {
    const Params output = root.scope("output");
    const std::optional<RunIdentity> continued = checkpoint_run(header, checkpoint);
    const std::string allowed =
        "the output.directory and output.prefix of the run the checkpoint continues, or a "
        "prefix with no files yet (the run is then continued there)";
    // What is already under the prefix: its run file, else its newest checkpoint (the one a
    // restart could write over or prune), else any other file of a run.
    std::vector<std::filesystem::path> others;
    std::filesystem::path witness;
    bool checkpoint_is_here = false;  // the checkpoint is one of this prefix's own files
    for (const auto& f : existing_run_files(s)) {
        if (same_file(f, checkpoint)) {
            checkpoint_is_here = true;
            continue;
        }
        const std::string name = f.filename().string();
        if (name == s.output.prefix + ".h5") witness = f;
        others.push_back(f);
    }
    if (others.empty()) return;
    if (witness.empty())
        for (auto it = others.rbegin(); it != others.rend() && witness.empty(); ++it)
            if (is_checkpoint_file_name(it->filename().string(), s.output.prefix)) witness = *it;
    if (witness.empty())
        output.fail("prefix",
                    fmt::format("restart={}: {} exists without a run file beside it: a restart "
                                "writes only into the run its checkpoint came from, and whose "
                                "run this file is cannot be told (nothing was written)",
                                checkpoint.string(), others.front().string()),
                    allowed);
    std::optional<RunIdentity> found;
    std::string why;
    try {
        if (is_checkpoint_file_name(witness.filename().string(), s.output.prefix))
            found = checkpoint_run(read_checkpoint_header(witness), witness);
        else
            found = read_run_identity(H5File::open(witness, false));
    } catch (const std::exception& e) {
        why = e.what();
    }
    if (found && continued && found->same_run(*continued)) return;
    // A run file that cannot be read (a job killed while writing it) beside the checkpoint
    // being restarted from, under the same prefix: that is this run's own folder, and the
    // restart puts the run file back from the checkpoint.
    if (!found && checkpoint_is_here && continued) return;
    const std::string theirs =
        found ? found->describe()
              : fmt::format("a run that cannot be told ({})",
                            why.empty() ? std::string("it stores no run file") : why);
    const std::string ours =
        continued ? continued->describe()
                  : std::string("a run that cannot be told: the checkpoint stores no run file");
    output.fail("prefix",
                fmt::format("restart={} would write into another run: {} belongs to {}; the "
                            "checkpoint continues {} (nothing was written)",
                            checkpoint.string(), witness.string(), theirs, ours),
                allowed);
}
#endif

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
