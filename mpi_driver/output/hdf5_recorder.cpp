#include "mpi_driver/output/hdf5_recorder.hpp"

#include <fcntl.h>
#include <unistd.h>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <numeric>
#include <system_error>

#include "core/error.hpp"
#include "core/io_error.hpp"
#include "mpi_driver/output/run_file_schema.hpp"
#include "mpi_driver/output/run_identity.hpp"

#include <fmt/format.h>

namespace efdem::mpi_driver {

namespace {
/// Bytes held in reserve for finishing the run file when the disk fills (its metadata and the
/// end attributes need far less).
constexpr off_t kReserveBytes = 1 << 20;

std::filesystem::path make_reserve(const std::filesystem::path& run_file) {
    const std::filesystem::path p = run_file.string() + ".reserve";
    const int fd = ::open(p.c_str(), O_CREAT | O_WRONLY | O_TRUNC, 0644);
    const int err = fd < 0 ? errno : ::posix_fallocate(fd, 0, kReserveBytes);
    if (fd >= 0) ::close(fd);
    if (err != 0) {
        std::error_code ignored;
        std::filesystem::remove(p, ignored);
        throw RuntimeFailure(io_failure_message(
            p, "the run file's 1 MiB reserve (space to finish it on a full disk)", err));
    }
    return p;
}

/// The run file, created (a new run) or opened (a restart); if that fails, the reserve is
/// released and a run file this run created is not left behind half made.
H5File open_or_release(const std::filesystem::path& path, const std::filesystem::path& reserve,
                       bool resume) {
    try {
        return resume ? H5File::open(path, true) : H5File::create(path);
    } catch (const std::exception&) {
        std::error_code ignored;
        std::filesystem::remove(reserve, ignored);
        if (!resume) std::filesystem::remove(path, ignored);
        throw;
    }
}

std::string now_utc() {
    const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}
std::span<const double> as_span(const Eigen::VectorXd& v) {
    return {v.data(), static_cast<std::size_t>(v.size())};
}
}  // namespace

Hdf5Recorder::Hdf5Recorder(const std::filesystem::path& directory, const std::string& prefix,
                           const RunProvenance& p, Eigen::Index coarse_dimension, bool resume)
    : path_(directory / (prefix + ".h5")),
      reserve_(make_reserve(path_)),
      file_(open_or_release(path_, reserve_, resume)),
      realizations_(p.realizations),
      m_(p.p_grid.size()),
      dim_(coarse_dimension),
      species_(p.species_names.size()),
      slabs_(static_cast<std::size_t>(p.profile_slabs)),
      si_pressure_(p.si.pressure) {
    // On a disk with room for the reserve but little more the first writes fail: the run file
    // must not be left unreadable or 'running', nor the reserve behind.
    try {
        start(p, resume);
    } catch (const std::exception& e) {
        std::error_code ignored;
        std::filesystem::remove(reserve_, ignored);
        try {
            file_.attribute("/", "end_status", std::string("failed: ") + e.what());
            file_.flush();
        } catch (const std::exception&) {
        }
        throw;
    }
}

void Hdf5Recorder::start(const RunProvenance& p, bool resume) {
    // What one reduced unit is in SI: the scene's, so also written into a run file put back
    // from a checkpoint written before these attributes existed.
    if (p.si.known()) {  // one reduced unit in SI, numbers a unit library can take
        file_.attribute("/", "si_length_m", p.si.length);
        file_.attribute("/", "si_time_s", p.si.time);
        file_.attribute("/", "si_velocity_m_per_s", p.si.velocity);
        file_.attribute("/", "si_acceleration_m_per_s2", p.si.acceleration);
        file_.attribute("/", "si_density_kg_per_m3", p.si.density);
        file_.attribute("/", "si_mass_kg", p.si.mass);
        file_.attribute("/", "si_pressure_Pa", p.si.pressure);
    }
    if (resume) {
        if (!file_.has_attribute("/", "format_version") ||
            file_.attribute_integer("/", "format_version") < kRunFileFormatVersion)
            upgrade(p);
        // A run file from before /bed/pressure_drop_pa: the column would start mid-run.
        if (file_.exists("/bed/pressure_drop") && !file_.exists("/bed/pressure_drop_pa"))
            si_pressure_ = std::numeric_limits<double>::quiet_NaN();
        // How this part of the run is executed (compare_runs.py ignores these).
        file_.attribute("/", "ranks", std::int64_t{p.ranks});
        file_.attribute("/", "realizations_per_rank", std::int64_t{p.realizations_per_rank});
        file_.attribute("/", "end_status", std::string("running"));
        file_.flush();
        return;
    }
    // Until finish() says how it ended: a reader can tell a run in progress, or one that was
    // killed, from a finished one.
    file_.attribute("/", "end_status", std::string("running"));
    file_.attribute("/", "format_version", kRunFileFormatVersion);
    file_.write_build_provenance();
    file_.attribute("/", "date", now_utc());
    // Which run this is: a restart writes only into the run its checkpoint came from.
    file_.attribute("/", "run_id", new_run_id());
    file_.attribute("/", "mode", p.mode);
    file_.attribute("/", "ranks", std::int64_t{p.ranks});
    file_.attribute("/", "realizations", std::int64_t{p.realizations});
    file_.attribute("/", "realizations_per_rank", std::int64_t{p.realizations_per_rank});
    file_.attribute("/", "seed", static_cast<std::int64_t>(p.seed));
    file_.attribute("/", "observed_species", p.observed_species);
    file_.attribute("/", "scene_file", p.scene_file);
    file_.attribute("/", "overrides", p.overrides);
    file_.write_text("/scene", p.scene_text);
    document("/scene");
    file_.write_text("/parameters", p.parameters);
    document("/parameters");
    file_.create_group("/samples");
    if (p.mode == "cpi") file_.create_group("/cpi");
    if (p.mode == "steady" || p.mode == "continuation" || p.hand_off) {
        file_.create_group("/steady");
        file_.create_group("/steady/iterate");
        if (p.mode == "continuation") file_.create_group("/branch");
    }
    if (species_ > 0) {
        file_.create_group("/bed");
        file_.create_group("/bed/ensemble_mean");
        file_.attribute("/bed", "weight_per_area", p.weight_per_area);
        file_.attribute("/bed", "profile_dz", p.profile_dz);
        file_.attribute("/bed", "mixing_layer", p.mixing_layer);
        file_.attribute("/bed", "mixing_species", p.observed_species);
    }
    ensure_axes(p);
    file_.flush();
}

void Hdf5Recorder::ensure_axes(const RunProvenance& p) {
    using T = H5Series::Type;
    auto reals = [&](const std::string& name, const std::vector<double>& v) {
        if (file_.exists(name)) return;
        file_.write(name, v, {static_cast<hsize_t>(v.size())});
        document(name);
    };
    auto texts = [&](const std::string& name, const std::vector<std::string>& v) {
        if (file_.exists(name)) return;
        file_.write_texts(name, v);
        document(name);
    };
    // A growing axis: a copy of `source`'s first `rows` rows (those of the arrays it labels).
    auto copy = [&](const std::string& name, const std::string& source, const std::string& rows) {
        if (file_.exists(name)) return;
        H5Series& s = series(name, {}, T::real);
        if (file_.exists(source) && file_.exists(rows))
            for (double v : file_.read_doubles(source, 0, file_.shape(rows).at(0))) s.append(v);
    };
    const std::vector<double> grid(p.p_grid.data(), p.p_grid.data() + p.p_grid.size());
    reals("/p", grid);
    index_axis("/realization", realizations_);
    series("/samples/time", {}, T::real);
    reals("/samples/p", grid);
    index_axis("/samples/realization", realizations_);
    texts("/samples/compact_parameter", {"A", "B", "C", "D"});
    if (file_.exists("/cpi")) {
        series("/cpi/t_start", {}, T::real);
        index_axis("/cpi/coarse_node", dim_);
        index_axis("/cpi/realization", realizations_);
    }
    if (file_.exists("/cpi/controller")) {
        copy("/cpi/controller/t_start", "/cpi/t_start", "/cpi/controller/accepted");
        index_axis("/cpi/controller/coarse_node", dim_);
    }
    if (file_.exists("/steady")) {
        index_axis("/steady/coarse_node", dim_);
        series("/steady/iterate/dem_time", {}, T::real);
        index_axis("/steady/iterate/coarse_node", dim_);
    }
    if (file_.exists("/branch")) {
        series("/branch/parameter", {}, T::real);
        index_axis("/branch/coarse_node", dim_);
    }
    if (file_.exists("/bed")) {
        std::vector<double> z(slabs_);
        for (std::size_t j = 0; j < slabs_; ++j)
            z[j] = (static_cast<double>(j) + 0.5) * p.profile_dz;
        copy("/bed/time", "/samples/time", "/bed/height");
        index_axis("/bed/realization", realizations_);
        reals("/bed/z", z);
        texts("/bed/species", p.species_names);
        copy("/bed/ensemble_mean/time", "/samples/time", "/bed/ensemble_mean/height");
        reals("/bed/ensemble_mean/z", z);
        texts("/bed/ensemble_mean/species", p.species_names);
    }
}

void Hdf5Recorder::upgrade(const RunProvenance& p) {
    file_.strip_dimension_scales();
    for (const auto& [from, to] : renamed_in_format_3())
        if (file_.exists(std::string(from)) && !file_.exists(std::string(to)))
            file_.move(std::string(from), std::string(to));
    // The axes there are first (the arrays attach them), then the added ones, then the rest.
    auto is_axis = [](const DatasetDoc& d) {
        return d.dims.size() == 1 && axis_of(d.path, d.dims[0]) == d.path;
    };
    std::vector<std::string> axes, arrays;
    for (const DatasetDoc& d : run_file_schema())
        if (file_.exists(std::string(d.path))) (is_axis(d) ? axes : arrays).emplace_back(d.path);
    for (const std::string& name : axes) document(name);
    ensure_axes(p);
    for (const std::string& name : arrays) document(name);
    file_.attribute("/", "format_version", kRunFileFormatVersion);
    file_.flush();
}

void Hdf5Recorder::index_axis(const std::string& name, Eigen::Index n) {
    if (file_.exists(name)) return;
    std::vector<std::int64_t> index(static_cast<std::size_t>(n));
    std::iota(index.begin(), index.end(), std::int64_t{0});
    file_.write(name, index, {static_cast<hsize_t>(n)});
    document(name);
}

void Hdf5Recorder::document(const std::string& name) {
    const DatasetDoc& d = dataset_doc(name);
    std::vector<std::string> labels, scales;
    for (std::string_view dim : d.dims) {
        labels.emplace_back(dim);
        scales.push_back(axis_of(name, dim));
    }
    file_.document(name, std::string(d.units), std::string(d.long_name), std::string(d.description),
                   labels, scales);
}

H5Series& Hdf5Recorder::series(const std::string& name, std::vector<hsize_t> row_shape,
                               H5Series::Type type) {
    auto it = series_.find(name);
    if (it == series_.end()) {
        const bool existing = file_.exists(name);  // a restarted run appends; documented when made
        it = series_
                 .emplace(name, existing ? H5Series::open(file_, name, type)
                                         : H5Series(file_, name, std::move(row_shape), type))
                 .first;
        if (!existing) {
            document(name);
            // A series that starts after its axis (one an older efdem did not record, in a run
            // file a restart continues) begins with a fill row for each earlier row of the axis
            // (NaN, -1 or empty text), so that its rows stay those of the axis. The axis got
            // this record's row first.
            const std::vector<std::string_view>& dims = dataset_doc(name).dims;
            const std::string axis = dims.empty() ? name : axis_of(name, dims[0]);
            if (axis != name && file_.exists(axis) && file_.shape(axis).at(0) > 1)
                fill_rows(it->second, type, file_.shape(axis).at(0) - 1);
        }
    }
    return it->second;
}

void Hdf5Recorder::fill_rows(H5Series& s, H5Series::Type type, hsize_t rows) {
    while (s.rows() < rows) {
        if (type == H5Series::Type::real)
            s.append(std::vector<double>(s.row_size(), std::numeric_limits<double>::quiet_NaN()));
        else if (type == H5Series::Type::integer)
            s.append(std::vector<std::int64_t>(s.row_size(), -1));
        else
            s.append_text("");
    }
}

void Hdf5Recorder::bed_sample(const SampleRecord& s) {
    using T = H5Series::Type;
    const auto r = static_cast<hsize_t>(realizations_), k = static_cast<hsize_t>(species_),
               n = static_cast<hsize_t>(slabs_);
    if (initial_height_.size() == 0) {
        // Expansion is relative to the run's first sample; a restarted run reads it back.
        initial_height_ = s.bed.height;
        if (file_.exists("/bed/height") && file_.shape("/bed/height")[0] > 0) {
            const auto first = file_.read_doubles("/bed/height", 0, 1);
            initial_height_ = Eigen::Map<const Eigen::VectorXd>(
                first.data(), static_cast<Eigen::Index>(first.size()));
        }
    }
    series("/bed/time", {}, T::real).append(s.time);
    series("/bed/ensemble_mean/time", {}, T::real).append(s.time);
    auto rows = [&](const std::string& group, const BedRecord& b, hsize_t members) {
        const std::vector<hsize_t> per =
            members > 1 || group == "/bed" ? std::vector<hsize_t>{members} : std::vector<hsize_t>{};
        series(group + "/pressure_drop", per, T::real).append(as_span(b.pressure_drop));
        if (std::isfinite(si_pressure_)) {
            const Eigen::VectorXd pa = b.pressure_drop * si_pressure_;
            series(group + "/pressure_drop_pa", per, T::real).append(as_span(pa));
        }
        series(group + "/pressure_drop_ratio", per, T::real).append(as_span(b.pressure_drop_ratio));
        series(group + "/height", per, T::real).append(as_span(b.height));
        series(group + "/mixing_index", per, T::real).append(as_span(b.mixing_index));
        const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>
            sh = b.species_height,
            phi = b.solid_fraction;
        auto with = [&](hsize_t last) {
            std::vector<hsize_t> shape = per;
            shape.push_back(last);
            return shape;
        };
        series(group + "/species_height", with(k), T::real)
            .append(std::span<const double>(sh.data(), static_cast<std::size_t>(sh.size())));
        series(group + "/solid_fraction", with(n), T::real)
            .append(std::span<const double>(phi.data(), static_cast<std::size_t>(phi.size())));
    };
    rows("/bed", s.bed, r);
    rows("/bed/ensemble_mean", s.bed_mean, 1);
    const Eigen::VectorXd expansion = s.bed.height.cwiseQuotient(initial_height_);
    series("/bed/expansion", {r}, T::real).append(as_span(expansion));
    // The mean's expansion: the mean height over the mean initial height of the realizations
    // now in the ensemble (NaN initial heights are those of no realization).
    double h0 = 0, used = 0;
    for (Eigen::Index i = 0; i < initial_height_.size(); ++i)
        if (std::isfinite(s.bed.height[i]) && std::isfinite(initial_height_[i])) {
            h0 += initial_height_[i];
            used += 1;
        }
    series("/bed/ensemble_mean/expansion", {}, T::real)
        .append(used > 0 ? s.bed_mean.height[0] / (h0 / used)
                         : std::numeric_limits<double>::quiet_NaN());
}

void Hdf5Recorder::sample(const SampleRecord& s) {
    using T = H5Series::Type;
    const auto m = static_cast<hsize_t>(m_), r = static_cast<hsize_t>(realizations_);
    series("/samples/time", {}, T::real).append(s.time);
    series("/samples/mean_icdf", {m}, T::real).append(as_span(s.mean));
    series("/samples/variance", {m}, T::real).append(as_span(s.variance));
    // Row-major R x m for the file.
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> icdf =
        s.realizations;
    series("/samples/icdf", {r, m}, T::real)
        .append(std::span<const double>(icdf.data(), static_cast<std::size_t>(icdf.size())));
    series("/samples/com", {r}, T::real).append(as_span(s.com));
    if (s.at_rest.size() == static_cast<Eigen::Index>(realizations_)) {
        std::vector<std::int64_t> rest(static_cast<std::size_t>(realizations_));
        for (std::size_t k = 0; k < rest.size(); ++k)
            rest[k] = s.at_rest[static_cast<Eigen::Index>(k)] == 1.0 ? 1 : 0;
        series("/samples/at_rest", {r}, T::integer).append(std::span<const std::int64_t>(rest));
    }
    series("/samples/realizations_used", {}, T::integer).append_integer(s.realizations_used);
    if (s.top_mean.size() == m_)
        series("/samples/top_mean", {m}, T::real).append(as_span(s.top_mean));
    if (s.compact.size() == 4) {
        series("/samples/compact", {4}, T::real).append(as_span(s.compact));
        series("/samples/compact_status", {}, T::integer).append_integer(s.compact_status);
    }
    // The records not every sample makes (the compact fit stops when its observable falls
    // back): a sample without one gets a fill row there, so that every array of /samples keeps
    // the rows of /samples/time.
    const hsize_t rows = series("/samples/time", {}, T::real).rows();
    for (const auto& [name, type] :
         {std::pair{"/samples/at_rest", T::integer}, std::pair{"/samples/top_mean", T::real},
          std::pair{"/samples/compact", T::real}, std::pair{"/samples/compact_status", T::integer}})
        if (file_.exists(name)) fill_rows(series(name, {}, type), type, rows);
    if (species_ > 0 && !s.bed.empty()) bed_sample(s);
    file_.flush();
}

void Hdf5Recorder::coarse_step(const coarse::ProjectiveStepRecord& rec, const LiftRecord& lift) {
    using T = H5Series::Type;
    const auto d = static_cast<hsize_t>(dim_), r = static_cast<hsize_t>(realizations_);
    auto scalar = [&](const char* name, double v) {
        series(fmt::format("/cpi/{}", name), {}, T::real).append(v);
    };
    auto integer = [&](const char* name, std::int64_t v) {
        series(fmt::format("/cpi/{}", name), {}, T::integer).append_integer(v);
    };
    scalar("t_start", rec.t_start);
    scalar("burst_length", rec.burst_length);
    scalar("healing", rec.healing);
    scalar("window", rec.window);
    scalar("dt_requested", rec.dt_requested);
    scalar("dt", rec.dt);
    scalar("period", rec.period);
    integer("periods", rec.periods_per_step);
    scalar("t_end", rec.t_end);
    series("/cpi/status", {}, T::text).append_text(std::string(coarse::to_string(rec.status)));
    series("/cpi/message", {}, T::text).append_text(rec.message);
    auto vec = [&](const char* name, const Eigen::VectorXd& v) {
        Eigen::VectorXd row =
            v.size() == dim_
                ? v
                : Eigen::VectorXd::Constant(dim_, std::numeric_limits<double>::quiet_NaN());
        series(fmt::format("/cpi/{}", name), {d}, T::real).append(as_span(row));
    };
    vec("slope", rec.slope);
    vec("slope_standard_error", rec.slope_standard_error);
    vec("x_end", rec.x_end);
    vec("x_projected", rec.x_projected);
    scalar("repair_max_adjustment", rec.repair.max_adjustment);
    integer("repair_clipped", rec.repair.n_clipped);
    integer("repair_non_monotone", rec.repair.non_monotone ? 1 : 0);
    integer("stability_assessed", rec.stability.assessed ? 1 : 0);
    integer("stability_stable", rec.stability.stable ? 1 : 0);
    scalar("stability_rate", rec.stability.rate);
    scalar("stability_amplification", rec.stability.amplification);
    if (const coarse::ControllerRecord& c = rec.controller; c.active) {
        // /cpi/controller/*: one row per coarse step of the multistep integrator (every row of
        // /cpi when it is the run's integrator). Errors RMS over the coarse vector [d_p].
        if (!file_.exists("/cpi/controller")) {
            file_.create_group("/cpi/controller");
            index_axis("/cpi/controller/coarse_node", dim_);
        }
        scalar("controller/t_start", rec.t_start);
        integer("controller/accepted", c.accepted ? 1 : 0);
        integer("controller/steps", c.steps);
        const std::pair<const char*, double> reals[] = {
            {"tolerance", c.tolerance},
            {"error_statistical", c.statistical},
            {"error_statistical_jump", c.statistical_jump},
            {"error_statistical_burst", c.statistical_burst},
            {"error_statistical_pool", c.statistical_pool},
            {"error_truncation", c.truncation},
            {"transient", c.transient},
            {"transient_threshold", c.transient_threshold},
            {"window_noise_ratio", c.window_noise_ratio},
            {"window_noise_correlation", c.window_noise_correlation},
            {"window_next", c.window_next},
            {"member_step", c.member_step},
            {"budget", c.budget},
            {"ensemble_standard_error", c.ensemble_standard_error},
            {"budget_spent", c.budget_spent},
            {"budget_walk", c.budget_walk},
            {"contraction_rate", c.contraction_rate},
            {"predicted_truncation", c.predicted_truncation},
            {"dt_tolerance", c.dt_tolerance},
            {"dt_tolerance_2r", c.dt_tolerance_2r},
            {"dt_tolerance_4r", c.dt_tolerance_4r}};
        for (const auto& [name, value] : reals)
            scalar(fmt::format("controller/{}", name).c_str(), value);
        series("/cpi/controller/limited_by", {}, T::text)
            .append_text(std::string(coarse::to_string(c.limited_by)));
        series("/cpi/controller/slope", {}, T::text)
            .append_text(std::string(coarse::to_string(c.slope_source)));
        integer("controller/pooled_bursts", c.pooled_bursts);
        vec("controller/error_statistical_nodes", c.statistical_nodes);
        vec("controller/error_truncation_nodes", c.truncation_nodes);
    }
    std::vector<std::int64_t> changed(static_cast<std::size_t>(realizations_), 0);
    std::vector<double> deviation(static_cast<std::size_t>(realizations_),
                                  std::numeric_limits<double>::quiet_NaN());
    std::vector<std::int64_t> at_rest(static_cast<std::size_t>(realizations_), 0);
    std::string messages;
    for (std::size_t k = 0; k < lift.changed.size() && k < changed.size(); ++k) {
        changed[k] = lift.changed[k];
        if (k < lift.at_rest.size()) at_rest[k] = lift.at_rest[k];
        deviation[k] = lift.max_deviation[k];
        if (!lift.messages[k].empty())
            messages += fmt::format("realization {}: {}\n", k, lift.messages[k]);
    }
    series("/cpi/lift_changed", {r}, T::integer).append(std::span<const std::int64_t>(changed));
    series("/cpi/lift_max_deviation", {r}, T::real).append(std::span<const double>(deviation));
    series("/cpi/lift_at_rest", {r}, T::integer).append(std::span<const std::int64_t>(at_rest));
    series("/cpi/lift_error", {}, T::real).append(lift.error);
    series("/cpi/lift_message", {}, T::text).append_text(messages);
    file_.flush();
}

void Hdf5Recorder::failure(const FailureRecord& f) {
    // /failures/*: one row per failure the run survived.
    using T = H5Series::Type;
    if (!file_.exists("/failures")) file_.create_group("/failures");
    series("/failures/time", {}, T::real).append(f.time);
    series("/failures/realization", {}, T::integer).append_integer(f.realization);
    series("/failures/action", {}, T::text).append_text(f.action);
    series("/failures/reason", {}, T::text).append_text(f.reason);
    series("/failures/donor", {}, T::integer).append_integer(f.donor);
    series("/failures/resumed_at", {}, T::real).append(f.resumed_at);
    series("/failures/realizations_left", {}, T::integer).append_integer(f.realizations_left);
    file_.flush();
}

void Hdf5Recorder::steady_iterate(const SteadyIterateRecord& it) {
    using T = H5Series::Type;
    series("/steady/iterate/dem_time", {}, T::real).append(it.dem_time);
    series("/steady/iterate/solve", {}, T::integer).append_integer(it.solve);
    series("/steady/iterate/iteration", {}, T::integer).append_integer(it.iteration);
    series("/steady/iterate/residual", {}, T::real).append(it.residual);
    series("/steady/iterate/noise", {}, T::real).append(it.noise);
    series("/steady/iterate/parameter", {}, T::real).append(it.parameter);
    series("/steady/iterate/x", {static_cast<hsize_t>(dim_)}, T::real).append(as_span(it.x));
    file_.flush();
}

void Hdf5Recorder::branch_point(const coarse::BranchPoint& p) {
    using T = H5Series::Type;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    series("/branch/parameter", {}, T::real).append(p.parameter);
    series("/branch/x", {static_cast<hsize_t>(dim_)}, T::real).append(as_span(p.x));
    series("/branch/residual", {}, T::real).append(p.residual);
    series("/branch/noise", {}, T::real).append(p.noise);
    series("/branch/mean_height", {}, T::real).append(coarse::mean_height(p.x));
    series("/branch/mean_height_error", {}, T::real)
        .append(coarse::mean_height_error_bound(p.noise, p.x.size()));
    series("/branch/newton_steps", {}, T::integer).append_integer(p.newton_iterations);
    series("/branch/arclength_step", {}, T::real).append(p.step);
    series("/branch/from_last_point", {}, T::integer).append_integer(p.from_fallback ? 1 : 0);
    series("/branch/leading_real", {}, T::real).append(p.has_leading ? p.leading.mu.real() : nan);
    series("/branch/leading_imag", {}, T::real).append(p.has_leading ? p.leading.mu.imag() : nan);
    series("/branch/leading_rate", {}, T::real).append(p.has_leading ? p.leading.rate : nan);
    series("/branch/leading_residual", {}, T::real)
        .append(p.has_leading ? p.leading.residual : nan);
    series("/branch/leading_noise", {}, T::real).append(p.has_leading ? p.leading.noise : nan);
    series("/branch/dem_time", {}, T::real).append(p.micro_time);
    file_.flush();
}

void Hdf5Recorder::steady_outcome(const coarse::SteadyRunOutcome& o) {
    const auto d = static_cast<hsize_t>(dim_);
    auto vector = [&](const char* name, const Eigen::VectorXd& v) {
        if (v.size() != dim_) return;  // e.g. no iterate before a signal
        file_.write(name, as_span(v), {d});
        document(name);
    };
    file_.attribute("/steady", "solver", o.solver);
    file_.attribute("/steady", "coordinates", o.coordinates);
    file_.attribute("/steady", "tau", o.tau);
    if (!o.difference_step_origin.empty()) {  // known once the warm-up is done
        file_.attribute("/steady", "difference_step", o.difference_step);
        file_.attribute("/steady", "difference_step_origin", o.difference_step_origin);
    }
    file_.attribute("/steady", "warmup_end", o.warmup_end);
    if (std::isfinite(o.hand_off_time)) {
        file_.attribute("/steady", "hand_off_time", o.hand_off_time);
        file_.attribute("/steady", "end_state_time", o.end_state_time);  // NaN: not reached
        // 1: a resumed run saw no burst outside the radius; the time is an upper bound.
        file_.attribute("/steady", "end_state_time_is_bound",
                        std::int64_t{o.end_state_time_is_bound ? 1 : 0});
    }
    file_.attribute("/steady", "evaluations", std::int64_t{o.evaluations});
    file_.attribute("/steady", "dem_time", o.micro_time);
    file_.attribute("/steady", "repairs", std::int64_t{o.repairs});
    file_.attribute("/steady", "largest_repair", o.largest_repair);
    file_.attribute("/steady", "converged", std::int64_t{o.converged ? 1 : 0});
    file_.attribute("/steady", "end_status", o.end_status);
    vector("/steady/x0", o.x0);
    if (o.continuation) {
        file_.attribute("/branch", "parameter", o.parameter);
        file_.attribute("/branch", "scale", o.parameter_scale);
        file_.attribute("/branch", "end_reason", o.branch.end_reason);
        std::vector<double> folds;
        for (const coarse::FoldEstimate& f : o.branch.folds())
            folds.push_back(f.parameter * o.parameter_scale);
        if (!folds.empty()) {
            index_axis("/branch/fold", static_cast<Eigen::Index>(folds.size()));
            file_.write("/branch/fold_parameter", folds, {static_cast<hsize_t>(folds.size())});
            document("/branch/fold_parameter");
        }
        if (o.branch.points.empty() &&
            o.solve.best.size() == dim_) {  // the first point did not converge
            file_.attribute("/steady", "best_residual", o.solve.best_state_residual());
            vector("/steady/best", o.solve.best);
        }
        file_.flush();
        return;
    }
    const coarse::SteadySolveRecord& r = o.solve;
    file_.attribute("/steady", "reason", coarse::to_string(r.reason));
    file_.attribute("/steady", "message", r.message);
    file_.attribute("/steady", "iterations", std::int64_t{r.iterations});
    file_.attribute("/steady", "best_residual",
                    r.best_state_residual());  // in heights, as /steady/iterate/residual
    vector("/steady/x", r.x);
    vector("/steady/best", r.best);
    if (r.best.size() == dim_)
        file_.attribute("/steady", "mean_height", coarse::mean_height(r.best));
    auto reals = [&](const char* name, const std::vector<double>& v) {
        file_.write(name, v, {static_cast<hsize_t>(v.size())});
        document(name);
    };
    auto integers = [&](const char* name, const std::vector<std::int64_t>& v) {
        file_.write(name, v, {static_cast<hsize_t>(v.size())});
        document(name);
    };
    auto size = [](const auto& v) { return static_cast<Eigen::Index>(v.size()); };
    if (!r.step_lengths.empty()) {
        index_axis("/steady/step", size(r.step_lengths));
        reals("/steady/step_length", r.step_lengths);
    }
    if (!r.krylov_iterations.empty()) {
        index_axis("/steady/newton_step", size(r.krylov_iterations));
        integers("/steady/krylov_products",
                 std::vector<std::int64_t>(r.krylov_iterations.begin(), r.krylov_iterations.end()));
        std::vector<double> res;
        std::vector<std::int64_t> step;
        for (std::size_t k = 0; k < r.gmres_residuals.size(); ++k)
            for (double v : r.gmres_residuals[k]) {
                res.push_back(v);
                step.push_back(static_cast<std::int64_t>(k));
            }
        index_axis("/steady/gmres_entry", size(res));
        reals("/steady/gmres_residual", res);
        integers("/steady/gmres_newton_step", step);
    }
    if (!o.spectrum.leading.empty()) {
        std::vector<double> re, im, rate, residual, noise;
        for (const coarse::CoarseEigenvalue& e : o.spectrum.leading) {
            re.push_back(e.mu.real());
            im.push_back(e.mu.imag());
            rate.push_back(e.rate);
            residual.push_back(e.residual);
            noise.push_back(e.noise);
        }
        index_axis("/steady/eigenvalue", size(re));
        reals("/steady/eigenvalue_real", re);
        reals("/steady/eigenvalue_imag", im);
        reals("/steady/eigenvalue_rate", rate);
        reals("/steady/eigenvalue_residual", residual);
        reals("/steady/eigenvalue_noise", noise);
        file_.attribute("/steady", "eigenvalue_products", std::int64_t{o.spectrum.products});
    }
    file_.flush();
}

void Hdf5Recorder::finish(const RunSummary& s) {
    // First free the reserve: if the disk filled, this is the space the end status and the
    // file's metadata are written into.
    std::error_code ignored;
    std::filesystem::remove(reserve_, ignored);
    file_.attribute("/", "end_status", s.end_status);
    file_.attribute("/", "simulated_time", s.simulated_time);
    file_.attribute("/", "dem_time", s.dem_time);
    file_.attribute("/", "wall_seconds", s.wall_seconds);
    file_.attribute("/", "resumed_wall_seconds", s.resumed_wall_seconds);
    file_.attribute("/", "settling_wall_seconds", s.settling_wall_seconds);
    file_.attribute("/", "total_wall_seconds", s.total_wall_seconds);
    file_.attribute("/", "particle_steps", s.particle_steps);
    file_.attribute("/", "coarse_steps", std::int64_t{s.coarse_steps});
    file_.attribute("/", "restrict_seconds", s.restrict_seconds);
    file_.attribute("/", "lift_seconds", s.lift_seconds);
    if (!s.controller.empty()) {
        file_.write_text("/cpi/controller_summary", s.controller);
        document("/cpi/controller_summary");
    }
    file_.flush();
}

}  // namespace efdem::mpi_driver
