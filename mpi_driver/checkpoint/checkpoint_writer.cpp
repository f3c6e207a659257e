#include "mpi_driver/checkpoint/checkpoint_writer.hpp"

#include <hdf5.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "core/contracts.hpp"
#include "core/error.hpp"
#include "mpi_driver/output/h5_file.hpp"

namespace efdem::mpi_driver {

namespace {
/// A warm-up until steady's last samples (only at a safe point inside one): /driver/warmup_tail/
/// t (n) and phase, expansion (n x R; each only where the samples have it).
void write_warmup_tail(H5File& f, const coarse::BurstSamples& tail) {
    if (tail.t.empty()) return;
    const std::string g = "/driver/warmup_tail/";
    f.create_group(g);
    f.write(g + "t", std::span<const double>(tail.t), {tail.t.size()});
    auto series = [&](const char* name, const std::vector<Eigen::VectorXd>& rows) {
        if (rows.empty()) return;
        EFDEM_ASSERT(rows.size() == tail.t.size());
        const auto r = static_cast<std::size_t>(rows.front().size());
        std::vector<double> all;
        for (const Eigen::VectorXd& v : rows) {
            EFDEM_ASSERT(static_cast<std::size_t>(v.size()) == r);
            all.insert(all.end(), v.data(), v.data() + r);
        }
        f.write(g + name, std::span<const double>(all), {rows.size(), r});
    };
    series("phase", tail.member_phase);
    series("expansion", tail.member_expansion);
}

/// The multistep integrator's state as named fields under /driver/integrator (format 4;
/// checkpoint_format.hpp lists them); nothing for an integrator without a state.
void write_integrator_state(H5File& f, const coarse::IntegratorState& state) {
    if (!state) return;
    const coarse::MultistepState& s = *state;
    const std::string g = "/driver/integrator/";
    for (const char* group : {"", "history", "decay", "controller", "totals"})
        f.create_group(g + group);
    auto real = [&](const std::string& name, double v) {
        f.write(g + name, std::span<const double>(&v, 1), {1});
    };
    auto integer = [&](const std::string& name, std::int64_t v) {
        f.write(g + name, std::span<const std::int64_t>(&v, 1), {1});
    };
    const auto m = static_cast<std::size_t>(s.x_end.size());
    real("t_end", s.t_end);
    f.write(g + "x_end", std::span<const double>(s.x_end.data(), m), {m});
    integer("curvature_only_front", s.curvature_only_front ? 1 : 0);
    f.write_text(g + "hold_kind", std::string(coarse::to_string(s.hold_kind)));
    f.write_text(g + "hold", s.hold);
    // Slope nodes as three arrays: tau (n), slope and se (n x m).
    auto write_nodes = [&](const std::string& group, auto&& node_of, const auto& list) {
        std::vector<double> tau, slope, se;
        for (const auto& item : list) {
            const coarse::SlopeNode& n = node_of(item);
            EFDEM_ASSERT(static_cast<std::size_t>(n.slope.size()) == m &&
                         static_cast<std::size_t>(n.se.size()) == m);
            tau.push_back(n.tau);
            slope.insert(slope.end(), n.slope.data(), n.slope.data() + m);
            se.insert(se.end(), n.se.data(), n.se.data() + m);
        }
        f.write(g + group + "/tau", std::span<const double>(tau), {tau.size()});
        f.write(g + group + "/slope", std::span<const double>(slope), {tau.size(), m});
        f.write(g + group + "/se", std::span<const double>(se), {tau.size(), m});
    };
    write_nodes(
        "history", [](const coarse::SlopeNode& n) -> const auto& { return n; }, s.history);
    f.create_group(g + "pool");
    write_nodes(
        "pool", [](const coarse::PooledBurst& b) -> const auto& { return b.node; }, s.pool);
    std::vector<double> commitment;
    for (const coarse::PooledBurst& b : s.pool) commitment.push_back(b.commitment);
    f.write(g + "pool/commitment", std::span<const double>(commitment), {commitment.size()});
    integer("decay/ok", s.decay.ok ? 1 : 0);
    real("decay/rate", s.decay.rate);
    real("decay/ratio", s.decay.ratio);
    real("decay/delay", s.decay.delay);
    f.write_text(g + "decay/message", s.decay.message);
    real("controller/dt_last", s.controller.dt_last);
    real("controller/dt_cap", s.controller.dt_cap);
    integer("controller/consecutive_rejections", s.controller.consecutive_rejections);
    const coarse::MultistepTotals& t = s.totals;
    integer("totals/attempts", t.attempts);
    integer("totals/accepted", t.accepted);
    integer("totals/rejected", t.rejected);
    integer("totals/direct", t.direct);
    real("totals/dt_taken", t.dt_taken);
    real("totals/dt_tolerance", t.dt_tolerance);
    real("totals/dt_tolerance_2r", t.dt_tolerance_2r);
    real("totals/dt_tolerance_4r", t.dt_tolerance_4r);
    real("totals/statistical", t.statistical);
    real("totals/truncation", t.truncation);
    real("healing", s.healing);
    if (s.member_deviation.size() > 0) {  // cpi.lift = own only; row-major R x m
        const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> d =
            s.member_deviation;
        const auto rows = static_cast<std::size_t>(d.rows()),
                   cols = static_cast<std::size_t>(d.cols());
        f.write(g + "member_deviation", std::span<const double>(d.data(), rows * cols),
                {rows, cols});
    }
    if (!std::isnan(s.budget.sigma)) {  // cpi.accuracy only
        f.create_group(g + "budget");
        real("budget/variance", s.budget.variance);
        real("budget/truncation", s.budget.truncation);
        real("budget/t_last", s.budget.t_last);
        real("budget/sigma", s.budget.sigma);
        real("budget/last_rate", s.budget.last_rate);
        real("budget/rate", s.budget.rate);
    }
    if (std::isnan(s.window)) return;  // cpi.window_auto only
    real("window", s.window);
    real("window_fast_time2", s.window_fast_time2);
    integer("window_measurements", s.window_measurements);
}
}  // namespace

namespace {
std::string read_whole_file(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    if (!in)
        throw RuntimeFailure(fmt::format("checkpoint: cannot read the output file {}", p.string()));
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::vector<double> flatten(const std::vector<Vec3>& v, std::size_t rows) {
    std::vector<double> out(3 * rows, 0.0);  // rows without data (no list, no history) stay zero
    for (std::size_t i = 0; i < v.size(); ++i) {
        out[3 * i] = v[i].x;
        out[3 * i + 1] = v[i].y;
        out[3 * i + 2] = v[i].z;
    }
    return out;
}

/// A parallel-HDF5 file being written collectively: shared datasets, each rank writing one
/// contiguous block of rows (its realizations are consecutive in global order).
class CollectiveFile {
  public:
    CollectiveFile(const std::filesystem::path& path, MPI_Comm comm) : path_(path.string()) {
        H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
        const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
        H5Pset_fapl_mpio(fapl, comm, MPI_INFO_NULL);
        file_ = H5Fcreate(path_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
        H5Pclose(fapl);
        if (file_ < 0)
            throw RuntimeFailure(fmt::format("cannot create the checkpoint file {}", path_));
        dxpl_ = H5Pcreate(H5P_DATASET_XFER);
        H5Pset_dxpl_mpio(dxpl_, H5FD_MPIO_COLLECTIVE);
        const hid_t g = H5Gcreate2(file_, "/realizations", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        if (g < 0)
            throw RuntimeFailure(fmt::format("HDF5 error in {}: create /realizations", path_));
        H5Gclose(g);
    }
    ~CollectiveFile() {
        if (dxpl_ >= 0) H5Pclose(dxpl_);
        if (file_ >= 0) H5Fclose(file_);
    }
    CollectiveFile(const CollectiveFile&) = delete;
    CollectiveFile& operator=(const CollectiveFile&) = delete;

    /// Dataset `name` of total_rows x width; this rank writes rows [first, first + rows).
    template <class T>
    void write_block(const std::string& name, hid_t type, hsize_t total_rows, hsize_t width,
                     hsize_t first, const std::vector<T>& data) {
        const hsize_t rows = width == 0 ? 0 : data.size() / width;
        const int rank = width == 1 ? 1 : 2;
        const hsize_t dims[2] = {total_rows, width};
        const hid_t fspace = H5Screate_simple(rank, dims, nullptr);
        const hid_t d =
            H5Dcreate2(file_, name.c_str(), type, fspace, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        herr_t status = d < 0 ? -1 : 0;
        if (status >= 0 && total_rows > 0) {
            const hsize_t start[2] = {first, 0}, count[2] = {rows, width};
            if (rows > 0)
                H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, nullptr, count, nullptr);
            else
                H5Sselect_none(fspace);
            const hsize_t mdims[2] = {std::max<hsize_t>(rows, 1), width};
            const hid_t mspace = H5Screate_simple(rank, mdims, nullptr);
            if (rows == 0) H5Sselect_none(mspace);
            status = H5Dwrite(d, type, mspace, fspace, dxpl_, rows > 0 ? data.data() : nullptr);
            H5Sclose(mspace);
        }
        if (d >= 0) H5Dclose(d);
        H5Sclose(fspace);
        if (status < 0)
            throw RuntimeFailure(fmt::format("HDF5 error in {}: write {}", path_, name));
    }

  private:
    std::string path_;
    hid_t file_ = -1;
    hid_t dxpl_ = -1;
};
}  // namespace

CheckpointWriter::CheckpointWriter(const EnsembleLayout& layout, const CheckpointSettings& settings,
                                   std::string prefix, CheckpointHeader identity,
                                   std::vector<std::filesystem::path> outputs)
    : layout_(layout),
      settings_(settings),
      prefix_(std::move(prefix)),
      identity_(std::move(identity)),
      outputs_(std::move(outputs)) {}

std::filesystem::path CheckpointWriter::write(long sequence,
                                              const std::vector<RealizationState>& local,
                                              const CheckpointHeader* header) const {
    const std::filesystem::path final_path =
        settings_.directory / checkpoint_file_name(prefix_, sequence);
    std::filesystem::path tmp = final_path;
    tmp += ".tmp";
    ensure_space(final_path, local);
    write_realizations(tmp, local);
    MPI_Barrier(layout_.mpi().comm());
    if (!layout_.is_root()) return final_path;
    if (settings_.debug_delay > 0)  // test hook: a window in which the job can be killed mid-write
        std::this_thread::sleep_for(std::chrono::duration<double>(settings_.debug_delay));
    try {
        write_header(tmp, sequence, *header);
    } catch (const std::exception&) {
        std::error_code ignored;
        std::filesystem::remove(tmp, ignored);  // a checkpoint that can never be whole
        throw;
    }
    std::error_code ec;
    std::filesystem::rename(tmp, final_path, ec);
    if (ec)
        throw RuntimeFailure(fmt::format("cannot rename the checkpoint {} to {}: {}", tmp.string(),
                                         final_path.string(), ec.message()));
    prune(final_path);
    return final_path;
}

void CheckpointWriter::ensure_space(const std::filesystem::path& path,
                                    const std::vector<RealizationState>& local) const {
    // A collective write that runs out of space can leave ranks waiting for each other in MPI-IO;
    // so the space is looked at first, and every rank gives up together if it is short.
    double bytes = 0;  // what this rank's rows take (x, v, omega, force, torque, reference, walls,
                       // tag, species; pairs)
    for (const auto& s : local)
        bytes += static_cast<double>(s.particles()) * (8 * sizeof(Vec3) + sizeof(dem::Tag) + 1) +
                 static_cast<double>(s.pairs.size()) * sizeof(dem::PairHistoryRecord);
    double total = 0;
    MPI_Allreduce(&bytes, &total, 1, MPI_DOUBLE, MPI_SUM, layout_.mpi().comm());
    double verdict[2] = {1.0, 0.0};  // ok, bytes free
    if (layout_.is_root()) {
        std::error_code ec;
        for (const auto& p : outputs_) {
            const auto size = std::filesystem::file_size(p, ec);
            if (!ec) total += static_cast<double>(size);
        }
        total = 1.25 * total + (1 << 20);  // HDF5 layout and metadata
        const auto space = std::filesystem::space(settings_.directory, ec);
        verdict[1] = ec ? -1.0 : static_cast<double>(space.available);
        verdict[0] = ec || verdict[1] >= total ? 1.0 : 0.0;
        verdict[1] = total - (ec ? 0.0 : verdict[1]);
    }
    MPI_Bcast(verdict, 2, MPI_DOUBLE, 0, layout_.mpi().comm());
    if (verdict[0] == 0.0)
        throw CheckpointSpaceError(
            fmt::format("cannot write the checkpoint {}: no space left on device for it ({:.3g} MB "
                        "more are needed; the disk "
                        "or the quota is full); the checkpoints already written are untouched",
                        path.string(), verdict[1] / 1e6));
}

void CheckpointWriter::write_realizations(const std::filesystem::path& tmp,
                                          const std::vector<RealizationState>& local) const {
    const MPI_Comm comm = layout_.mpi().comm();
    const int k = layout_.per_rank(), total = layout_.size();
    std::vector<long> mine, all(static_cast<std::size_t>(2 * total));
    for (const auto& s : local) {
        mine.push_back(static_cast<long>(s.particles()));
        mine.push_back(static_cast<long>(s.pairs.size()));
    }
    MPI_Allgather(mine.data(), 2 * k, MPI_LONG, all.data(), 2 * k, MPI_LONG, comm);
    hsize_t n_total = 0, p_total = 0, n_first = 0, p_first = 0;
    for (int r = 0; r < total; ++r) {
        if (r == layout_.first_index()) {
            n_first = n_total;
            p_first = p_total;
        }
        n_total += static_cast<hsize_t>(all[2 * r]);
        p_total += static_cast<hsize_t>(all[2 * r + 1]);
    }

    std::vector<std::int64_t> meta, checksum, tags, pair_tags, still;
    std::vector<double> time, pair_xi;
    std::vector<std::uint8_t> species;
    std::vector<double> blocks[8];  // x, v, omega, force, torque, reference, wall_floor, wall_lid
    for (const auto& s : local) {
        const std::size_t n = s.particles();
        meta.insert(meta.end(), {s.index, s.step, static_cast<std::int64_t>(n),
                                 static_cast<std::int64_t>(s.pairs.size()),
                                 s.reference.empty() ? 0 : 1, s.wall[0].empty() ? 0 : 1});
        checksum.push_back(to_stored(s.checksum()));
        still.push_back(s.still_samples);
        time.push_back(s.time);
        const std::vector<Vec3>* arrays[8] = {&s.x,      &s.v,         &s.omega,   &s.force,
                                              &s.torque, &s.reference, &s.wall[0], &s.wall[1]};
        for (int a = 0; a < 8; ++a) {
            const auto flat = flatten(*arrays[a], n);
            blocks[a].insert(blocks[a].end(), flat.begin(), flat.end());
        }
        tags.insert(tags.end(), s.tag.begin(), s.tag.end());
        species.insert(species.end(), s.species.begin(), s.species.end());
        for (const auto& p : s.pairs) {
            pair_tags.insert(pair_tags.end(), {p.tag_i, p.tag_j});
            pair_xi.insert(pair_xi.end(), {p.xi.x, p.xi.y, p.xi.z});
        }
    }
    CollectiveFile f(tmp, comm);
    const auto R = static_cast<hsize_t>(total);
    const auto first = static_cast<hsize_t>(layout_.first_index());
    f.write_block("/realizations/meta", H5T_NATIVE_INT64, R, 6, first, meta);
    f.write_block("/realizations/checksum", H5T_NATIVE_INT64, R, 1, first, checksum);
    f.write_block("/realizations/still_samples", H5T_NATIVE_INT64, R, 1, first, still);
    f.write_block("/realizations/time", H5T_NATIVE_DOUBLE, R, 1, first, time);
    const char* names[8] = {"x",      "v",         "omega",      "force",
                            "torque", "reference", "wall_floor", "wall_lid"};
    for (int a = 0; a < 8; ++a)
        f.write_block(fmt::format("/realizations/{}", names[a]), H5T_NATIVE_DOUBLE, n_total, 3,
                      n_first, blocks[a]);
    f.write_block("/realizations/tag", H5T_NATIVE_INT64, n_total, 1, n_first, tags);
    f.write_block("/realizations/species", H5T_NATIVE_UINT8, n_total, 1, n_first, species);
    f.write_block("/realizations/pair_tags", H5T_NATIVE_INT64, p_total, 2, p_first, pair_tags);
    f.write_block("/realizations/pair_xi", H5T_NATIVE_DOUBLE, p_total, 3, p_first, pair_xi);
}

void CheckpointWriter::write_header(const std::filesystem::path& tmp, long sequence,
                                    const CheckpointHeader& state) const {
    CheckpointHeader h = identity_;
    h.sequence = sequence;
    h.stepper = state.stepper;
    h.driver = state.driver;
    for (const auto& p : outputs_)
        if (std::filesystem::exists(p))  // stored by what follows the prefix: restarts may rename
            h.outputs.push_back({p.filename().string().substr(prefix_.size()), read_whole_file(p)});
    // In the order a reader lists them (by name), so that the checksum is computed alike.
    std::sort(h.outputs.begin(), h.outputs.end(),
              [](const auto& a, const auto& b) { return a.name < b.name; });

    H5File f = H5File::open(tmp, true);
    f.attribute("/", "format_version", h.format_version);
    f.write_build_provenance();
    f.attribute("/", "mode", h.mode);
    f.attribute("/", "realizations", std::int64_t{h.realizations});
    f.attribute("/", "sequence", std::int64_t{h.sequence});
    f.write_text("/scene", h.scene_text);
    f.write_text("/parameters", h.parameters);
    f.create_group("/driver");
    const StepperState& s = h.stepper;
    const std::vector<double> reals{h.driver.t_origin, s.micro_time, s.particle_steps, s.height_lo,
                                    s.height_hi};
    f.write("/driver/reals", std::span<const double>(reals), {reals.size()});
    const std::vector<std::int64_t> integers{s.samples_taken, h.driver.coarse_steps,
                                             h.driver.without_progress, h.driver.fell_back ? 1 : 0,
                                             h.driver.warmed_up ? 1 : 0};
    f.write("/driver/integers", std::span<const std::int64_t>(integers), {integers.size()});
    const std::vector<double> warmup_done{h.driver.warmup_done};
    f.write("/driver/warmup_done", std::span<const double>(warmup_done), {1});
    write_warmup_tail(f, h.driver.warmup_tail);
    std::vector<std::int64_t> lifting;
    for (const auto& st : s.lifting)
        for (std::uint64_t w : st) lifting.push_back(to_stored(w));
    f.write("/driver/lifting", std::span<const std::int64_t>(lifting), {s.lifting.size(), 4});
    f.write("/driver/active", std::span<const std::int64_t>(s.active), {s.active.size()});
    const std::vector<std::int64_t> failures{s.failures};
    f.write("/driver/failures", std::span<const std::int64_t>(failures), {1});
    f.write("/driver/observable", std::span<const double>(s.observable), {s.observable.size()});
    f.write("/driver/recorded", std::span<const double>(s.recorded), {s.recorded.size()});
    write_integrator_state(f, h.driver.integrator);
    f.create_group("/output");
    for (const auto& o : h.outputs)
        f.write_bytes("/output/" + o.name,
                      std::span<const std::uint8_t>(
                          reinterpret_cast<const std::uint8_t*>(o.bytes.data()), o.bytes.size()));
    f.attribute("/", "header_checksum", to_stored(h.checksum()));
    f.flush();
    f.attribute("/", "complete", std::int64_t{1});  // last: marks the file as whole
    f.flush();
}

void CheckpointWriter::prune(const std::filesystem::path& current) const {
    std::vector<std::filesystem::path> found;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(settings_.directory, ec)) {
        const std::string name = e.path().filename().string();
        if (is_checkpoint_file_name(name, prefix_)) found.push_back(e.path());
        // Left by a job killed while writing; never a restart candidate.
        else if (name.ends_with(".h5.tmp") &&
                 is_checkpoint_file_name(name.substr(0, name.size() - 4), prefix_))
            std::filesystem::remove(e.path(), ec);
    }
    std::sort(found.begin(), found.end());
    const auto keep = static_cast<std::size_t>(settings_.keep);
    for (std::size_t i = 0; i + keep < found.size(); ++i)
        if (found[i] != current) std::filesystem::remove(found[i], ec);
}

}  // namespace efdem::mpi_driver
