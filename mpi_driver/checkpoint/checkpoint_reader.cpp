#include "mpi_driver/checkpoint/checkpoint_reader.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/file_kind.hpp"
#include "mpi_driver/output/h5_file.hpp"

namespace efdem::mpi_driver {

namespace {
[[noreturn]] void refuse(const std::filesystem::path& path, const std::string& problem) {
    throw InputError(SourceLocation{path.string(), 0}, "checkpoint " + problem);
}

/// What a `.tmp` is, however far its writing got before the job was killed.
constexpr const char* kPartialWrite =
    "is incomplete: a .tmp file left by an interrupted write (use the previous checkpoint)";

/// Runs `body` on the opened file; any HDF5 failure becomes an InputError naming the file.
template <class T>
T with_checkpoint(const std::filesystem::path& path, const std::function<T(const H5File&)>& body) {
    if (const std::string what = not_a_regular_file(path); !what.empty())
        refuse(path, what == "file not found" ? "file not found (restart=FILE names no file)"
                                              : what + " (restart=FILE names a checkpoint file)");
    try {
        const H5File f = H5File::open(path, false);
        return body(f);
    } catch (const RuntimeFailure& e) {
        if (path.extension() == ".tmp") refuse(path, kPartialWrite);
        refuse(path, fmt::format("cannot be read: it is truncated or corrupted ({})", e.what()));
    }
}

/// A warm-up until steady's last samples (checkpoint_format.hpp).
coarse::BurstSamples read_warmup_tail(const H5File& f, const std::filesystem::path& path) {
    const std::string g = "/driver/warmup_tail/";
    coarse::BurstSamples tail;
    tail.t = f.read_doubles(g + "t");
    auto series = [&](const char* name) {
        std::vector<Eigen::VectorXd> rows;
        if (!f.exists(g + name)) return rows;
        const std::vector<double> all = f.read_doubles(g + name);
        const std::size_t n = tail.t.size();
        if (n == 0 || all.size() % n != 0)
            refuse(path, fmt::format("has a malformed {}{} dataset ({} values for {} samples)", g,
                                     name, all.size(), n));
        const auto r = static_cast<Eigen::Index>(all.size() / n);
        for (std::size_t i = 0; i < n; ++i)
            rows.emplace_back(
                Eigen::Map<const Eigen::VectorXd>(all.data() + i * static_cast<std::size_t>(r), r));
        return rows;
    };
    tail.member_phase = series("phase");
    tail.member_expansion = series("expansion");
    return tail;
}

/// The multistep integrator's state from its named fields (format 4; checkpoint_format.hpp).
coarse::MultistepState read_integrator_state(const H5File& f, const std::filesystem::path& path) {
    const std::string g = "/driver/integrator/";
    auto values = [&](const std::string& name, std::size_t size) {
        std::vector<double> v = f.read_doubles(g + name);
        if (v.size() != size)
            refuse(path, fmt::format("has a malformed {}{} dataset ({} values, {} expected)", g,
                                     name, v.size(), size));
        return v;
    };
    auto real = [&](const std::string& name) { return values(name, 1)[0]; };
    auto integer = [&](const std::string& name) {
        const std::vector<std::int64_t> v = f.read_integers(g + name);
        if (v.size() != 1) refuse(path, "has a malformed " + g + name + " dataset");
        return v[0];
    };
    coarse::MultistepState s;
    s.t_end = real("t_end");
    const std::vector<double> x = f.read_doubles(g + "x_end");
    const auto m = static_cast<Eigen::Index>(x.size());
    s.x_end = Eigen::Map<const Eigen::VectorXd>(x.data(), m);
    s.curvature_only_front = integer("curvature_only_front") != 0;
    const std::string kind = f.read_text(g + "hold_kind");
    const std::optional<coarse::DtLimit> hold_kind = coarse::dt_limit_from_string(kind);
    if (!hold_kind) refuse(path, "names an unknown " + g + "hold_kind '" + kind + "'");
    s.hold_kind = *hold_kind;
    s.hold = f.read_text(g + "hold");
    // Slope nodes from their three arrays: tau (n), slope and se (n x m).
    auto read_nodes = [&](const std::string& group) {
        const std::vector<double> tau = f.read_doubles(g + group + "/tau");
        const std::size_t n = tau.size(), mm = x.size();
        const std::vector<double> slope = values(group + "/slope", n * mm),
                                  se = values(group + "/se", n * mm);
        std::vector<coarse::SlopeNode> nodes;
        for (std::size_t i = 0; i < n; ++i)
            nodes.push_back({tau[i], Eigen::Map<const Eigen::VectorXd>(slope.data() + i * mm, m),
                             Eigen::Map<const Eigen::VectorXd>(se.data() + i * mm, m)});
        return nodes;
    };
    s.history = read_nodes("history");
    if (f.exists(g + "healing")) s.healing = real("healing");  // since cpi.healing_auto
    if (f.exists(g + "lift_reserve")) s.lift_reserve = real("lift_reserve");  // since issue 37
    if (f.exists(g + "realizations"))                                         // since cpi.curvature
        s.realizations = static_cast<int>(integer("realizations"));
    if (f.exists(g + "member_deviation")) {  // cpi.lift = own runs: R x m, row-major
        const std::vector<double> d = f.read_doubles(g + "member_deviation");
        if (x.empty() || d.size() % x.size() != 0)
            refuse(path, "has a malformed " + g + "member_deviation dataset");
        s.member_deviation = Eigen::Map<
            const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            d.data(), static_cast<Eigen::Index>(d.size() / x.size()), m);
    }
    if (f.exists(g + "budget/sigma")) {  // cpi.accuracy runs
        s.budget.variance = real("budget/variance");
        s.budget.truncation = real("budget/truncation");
        s.budget.t_last = real("budget/t_last");
        s.budget.sigma = real("budget/sigma");
        s.budget.last_rate = real("budget/last_rate");
        s.budget.rate = real("budget/rate");
    }
    if (f.exists(g + "window")) {  // cpi.window_auto runs
        s.window = real("window");
        s.window_fast_time2 = real("window_fast_time2");
        s.window_measurements = static_cast<int>(integer("window_measurements"));
    }
    if (f.exists(g + "pool/tau")) {  // written since cpi.slope = pooled
        std::vector<coarse::SlopeNode> nodes = read_nodes("pool");
        const std::vector<double> commitment = values("pool/commitment", nodes.size());
        for (std::size_t i = 0; i < nodes.size(); ++i)
            s.pool.push_back({std::move(nodes[i]), commitment[i]});
    }
    s.decay.ok = integer("decay/ok") != 0;
    s.decay.rate = real("decay/rate");
    s.decay.ratio = real("decay/ratio");
    s.decay.delay = real("decay/delay");
    s.decay.message = f.read_text(g + "decay/message");
    s.controller.dt_last = real("controller/dt_last");
    s.controller.dt_cap = real("controller/dt_cap");
    s.controller.consecutive_rejections = integer("controller/consecutive_rejections");
    coarse::MultistepTotals& t = s.totals;
    t.attempts = integer("totals/attempts");
    t.accepted = integer("totals/accepted");
    t.rejected = integer("totals/rejected");
    t.direct = integer("totals/direct");
    t.dt_taken = real("totals/dt_taken");
    t.dt_tolerance = real("totals/dt_tolerance");
    t.dt_tolerance_2r = real("totals/dt_tolerance_2r");
    t.dt_tolerance_4r = real("totals/dt_tolerance_4r");
    t.statistical = real("totals/statistical");
    t.truncation = real("totals/truncation");
    return s;
}

std::vector<Vec3> vectors(const std::vector<double>& flat) {
    std::vector<Vec3> out(flat.size() / 3);
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = {flat[3 * i], flat[3 * i + 1], flat[3 * i + 2]};
    return out;
}
}  // namespace

double read_checkpoint_time(const std::filesystem::path& path) {
    return with_checkpoint<double>(path, [&](const H5File& f) {
        const std::vector<double> times = f.read_doubles("/realizations/time");
        if (times.empty()) refuse(path, "holds no realization");
        return *std::max_element(times.begin(), times.end());
    });
}

CheckpointHeader read_checkpoint_header(const std::filesystem::path& path) {
    return with_checkpoint<CheckpointHeader>(path, [&](const H5File& f) {
        if (f.exists("/samples") && !f.exists("/realizations"))
            throw InputError(
                SourceLocation{path.string(), 0},
                "restart= names an efdem run file (the record of a run), not a checkpoint; "
                "checkpoints "
                "are the PREFIX_ckpt_NNNNNNNN.h5 files in checkpoint.directory (written every "
                "checkpoint.interval and when a stop signal ends a run)");
        if (!f.has_attribute("/", "format_version"))
            refuse(path, path.extension() == ".tmp"
                             ? kPartialWrite
                             : "is not an efdem checkpoint (no format_version attribute)");
        CheckpointHeader h;
        h.format_version = f.attribute_integer("/", "format_version");
        if (h.format_version < kOldestReadableCheckpointFormat ||
            h.format_version > kCheckpointFormatVersion)
            refuse(path, fmt::format("has format version {}; this efdem reads versions {} to {}",
                                     h.format_version, kOldestReadableCheckpointFormat,
                                     kCheckpointFormatVersion));
        if (!f.has_attribute("/", "complete") || f.attribute_integer("/", "complete") != 1)
            refuse(path,
                   "is incomplete: its writing was interrupted (use the previous checkpoint)");
        h.mode = f.attribute_text("/", "mode");
        h.realizations = f.attribute_integer("/", "realizations");
        h.sequence = f.attribute_integer("/", "sequence");
        h.scene_text = f.read_text("/scene");
        h.parameters = f.read_text("/parameters");
        const auto reals = f.read_doubles("/driver/reals");
        const auto integers = f.read_integers("/driver/integers");
        if (reals.size() != 5 || integers.size() != (h.format_version >= 3 ? 5U : 4U))
            refuse(path, "has a malformed /driver group");
        h.driver.t_origin = reals[0];
        h.stepper.micro_time = reals[1];
        h.stepper.particle_steps = reals[2];
        h.stepper.height_lo = reals[3];
        h.stepper.height_hi = reals[4];
        h.stepper.samples_taken = integers[0];
        h.driver.coarse_steps = integers[1];
        h.driver.without_progress = integers[2];
        h.driver.fell_back = integers[3] != 0;
        // Before format 3 checkpoints were only written after the warm-up.
        h.driver.warmed_up = h.format_version < 3 || integers[4] != 0;
        if (f.exists("/driver/wall_seconds")) {  // written since efdem keeps it
            const auto wall = f.read_doubles("/driver/wall_seconds");
            if (wall.size() != 1 || !(wall[0] >= 0))
                refuse(path, "has a malformed /driver/wall_seconds");
            h.stepper.wall_seconds = wall[0];
        }
        if (f.exists("/driver/warmup_done")) {  // written since the warm-up has safe points
            const auto done = f.read_doubles("/driver/warmup_done");
            if (done.size() != 1 || !(done[0] >= 0))
                refuse(path, "has a malformed /driver/warmup_done");
            h.driver.warmup_done = done[0];
        }
        if (f.exists("/driver/warmup_tail")) h.driver.warmup_tail = read_warmup_tail(f, path);
        if (f.exists("/driver/drift")) {  // cpi.finish = steady's pool (DriftTest::save())
            h.driver.drift = f.read_doubles("/driver/drift");
            const std::vector<double>& d = h.driver.drift;
            // [quiet checks, components, then per burst tau, slope, se]
            auto count = [](double v) { return v >= 0 && v <= 1e6 && v == std::floor(v); };
            if (d.size() < 2 || !count(d[0]) || !count(d[1]) || d[1] < 1 ||
                (d.size() - 2) % (1 + 2 * static_cast<std::size_t>(d[1])) != 0)
                refuse(path, "has a malformed /driver/drift dataset");
        }
        const auto lifting = f.read_integers("/driver/lifting");
        if (lifting.size() != static_cast<std::size_t>(4 * h.realizations))
            refuse(path, "has a malformed /driver/lifting dataset");
        if (h.format_version >= 3) {
            h.stepper.active = f.read_integers("/driver/active");
            const auto failures = f.read_integers("/driver/failures");
            if (h.stepper.active.size() != static_cast<std::size_t>(h.realizations) ||
                failures.size() != 1)
                refuse(path, "has a malformed /driver/active or /driver/failures dataset");
            h.stepper.failures = failures[0];
        }
        for (std::size_t r = 0; r < lifting.size(); r += 4)
            h.stepper.lifting.push_back({from_stored(lifting[r]), from_stored(lifting[r + 1]),
                                         from_stored(lifting[r + 2]), from_stored(lifting[r + 3])});
        h.stepper.observable = f.read_doubles("/driver/observable");
        h.stepper.recorded = f.read_doubles("/driver/recorded");
        if (h.format_version >= 4) {
            if (f.exists("/driver/integrator"))
                h.driver.integrator = read_integrator_state(f, path);
        } else if (h.format_version >= 2) {
            h.integrator_layout = f.read_doubles("/driver/integrator");
            h.integrator_layout_text = f.read_text("/driver/integrator_text");
        }
        for (const std::string& name : f.members("/output")) {
            const auto bytes = f.read_bytes("/output/" + name);
            h.outputs.push_back({name, std::string(bytes.begin(), bytes.end())});
        }
        if (!f.has_attribute("/", "header_checksum") ||
            from_stored(f.attribute_integer("/", "header_checksum")) != h.checksum())
            refuse(path, "is corrupted: the checksum of its root-level state does not match");
        // Formats 2 and 3: the positional state, by name (empty: a single-step integrator's).
        if (!h.integrator_layout.empty()) {
            try {
                h.driver.integrator = coarse::MultistepState::from_layout(h.integrator_layout,
                                                                          h.integrator_layout_text);
            } catch (const std::invalid_argument& e) {
                refuse(path, e.what());
            }
        }
        return h;
    });
}

std::vector<RealizationState> read_checkpoint_realizations(const std::filesystem::path& path,
                                                           long first, int count) {
    return with_checkpoint<std::vector<RealizationState>>(path, [&](const H5File& f) {
        const auto meta = f.read_integers("/realizations/meta");
        const auto rows = static_cast<long>(meta.size() / 6);
        if (first + count > rows)
            refuse(path, fmt::format("holds {} realizations; realization {} was asked for", rows,
                                     first + count - 1));
        const auto checksum = f.read_integers("/realizations/checksum");
        const auto time = f.read_doubles("/realizations/time");
        // Written since the rest judgement (ensemble.at_rest); before it, none was still.
        const auto still = f.exists("/realizations/still_samples")
                               ? f.read_integers("/realizations/still_samples")
                               : std::vector<std::int64_t>(static_cast<std::size_t>(rows), 0);
        hsize_t n_off = 0, p_off = 0;
        for (long r = 0; r < first; ++r) {
            n_off += static_cast<hsize_t>(meta[6 * r + 2]);
            p_off += static_cast<hsize_t>(meta[6 * r + 3]);
        }
        std::vector<RealizationState> out;
        for (long r = first; r < first + count; ++r) {
            const std::int64_t* m = &meta[static_cast<std::size_t>(6 * r)];
            const auto n = static_cast<hsize_t>(m[2]), np = static_cast<hsize_t>(m[3]);
            RealizationState s;
            s.index = m[0];
            s.step = m[1];
            s.time = time.at(static_cast<std::size_t>(r));
            s.still_samples = still.at(static_cast<std::size_t>(r));
            auto block = [&](const char* name) {
                return vectors(f.read_doubles(fmt::format("/realizations/{}", name), n_off, n));
            };
            s.x = block("x");
            s.v = block("v");
            s.omega = block("omega");
            s.force = block("force");
            s.torque = block("torque");
            if (m[4] != 0) s.reference = block("reference");
            if (m[5] != 0) {
                s.wall[0] = block("wall_floor");
                s.wall[1] = block("wall_lid");
            }
            const auto tags = f.read_integers("/realizations/tag", n_off, n);
            s.tag.assign(tags.begin(), tags.end());
            const auto species = f.read_bytes("/realizations/species", n_off, n);
            s.species.assign(species.begin(), species.end());
            const auto pt = f.read_integers("/realizations/pair_tags", p_off, np);
            const auto px = f.read_doubles("/realizations/pair_xi", p_off, np);
            if (pt.size() != 2 * np || px.size() != 3 * np || s.x.size() != n)
                refuse(path, fmt::format("realization {} is truncated", r));
            for (hsize_t k = 0; k < np; ++k)
                s.pairs.push_back(
                    {pt[2 * k], pt[2 * k + 1], {px[3 * k], px[3 * k + 1], px[3 * k + 2]}});
            if (s.checksum() != from_stored(checksum.at(static_cast<std::size_t>(r))))
                refuse(path, fmt::format(
                                 "is corrupted: the checksum of realization {} does not match", r));
            out.push_back(std::move(s));
            n_off += n;
            p_off += np;
        }
        return out;
    });
}

}  // namespace efdem::mpi_driver
