#include "mpi_driver/checkpoint/checkpoint_writer.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "core/contracts.hpp"
#include "core/error.hpp"
#include "mpi_driver/output/h5_file.hpp"
#include "mpi_driver/parallel/mpi_broadcast.hpp"

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
    real("lift_reserve", s.lift_reserve);
    integer("realizations", s.realizations);
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

/// Where one realization's rows start in the /realizations datasets.
struct RowStart {
    hsize_t realization = 0, particle = 0, pair = 0;
};

/// The /realizations datasets of a checkpoint the root writes alone: created at their full
/// sizes, then filled one realization at a time (rows in global realization order).
class RealizationTable {
  public:
    RealizationTable(H5File& f, hsize_t realizations, hsize_t particles, hsize_t pairs) : f_(f) {
        f.create_group("/realizations");
        create("meta", H5T_NATIVE_INT64, realizations, 6);
        create("checksum", H5T_NATIVE_INT64, realizations, 1);
        create("still_samples", H5T_NATIVE_INT64, realizations, 1);
        create("time", H5T_NATIVE_DOUBLE, realizations, 1);
        for (const char* name : kVectors) create(name, H5T_NATIVE_DOUBLE, particles, 3);
        create("tag", H5T_NATIVE_INT64, particles, 1);
        create("species", H5T_NATIVE_UINT8, particles, 1);
        create("pair_tags", H5T_NATIVE_INT64, pairs, 2);
        create("pair_xi", H5T_NATIVE_DOUBLE, pairs, 3);
    }

    void write(const RealizationState& s, RowStart at) {
        const std::size_t n = s.particles();
        const std::vector<std::int64_t> meta{s.index,
                                             s.step,
                                             static_cast<std::int64_t>(n),
                                             static_cast<std::int64_t>(s.pairs.size()),
                                             s.reference.empty() ? 0 : 1,
                                             s.wall[0].empty() ? 0 : 1};
        rows("meta", H5T_NATIVE_INT64, at.realization, 6, meta);
        rows("checksum", H5T_NATIVE_INT64, at.realization, 1,
             std::vector<std::int64_t>{to_stored(s.checksum())});
        rows("still_samples", H5T_NATIVE_INT64, at.realization, 1,
             std::vector<std::int64_t>{s.still_samples});
        rows("time", H5T_NATIVE_DOUBLE, at.realization, 1, std::vector<double>{s.time});
        const std::vector<Vec3>* arrays[8] = {&s.x,      &s.v,         &s.omega,   &s.force,
                                              &s.torque, &s.reference, &s.wall[0], &s.wall[1]};
        for (int a = 0; a < 8; ++a)
            rows(kVectors[a], H5T_NATIVE_DOUBLE, at.particle, 3, flatten(*arrays[a], n));
        rows("tag", H5T_NATIVE_INT64, at.particle, 1,
             std::vector<std::int64_t>(s.tag.begin(), s.tag.end()));
        rows("species", H5T_NATIVE_UINT8, at.particle, 1, s.species);
        std::vector<std::int64_t> pair_tags;
        std::vector<double> pair_xi;
        for (const auto& p : s.pairs) {
            pair_tags.insert(pair_tags.end(), {p.tag_i, p.tag_j});
            pair_xi.insert(pair_xi.end(), {p.xi.x, p.xi.y, p.xi.z});
        }
        rows("pair_tags", H5T_NATIVE_INT64, at.pair, 2, pair_tags);
        rows("pair_xi", H5T_NATIVE_DOUBLE, at.pair, 3, pair_xi);
    }

  private:
    static constexpr const char* kVectors[8] = {"x",      "v",         "omega",      "force",
                                                "torque", "reference", "wall_floor", "wall_lid"};

    void create(const std::string& name, hid_t type, hsize_t total_rows, hsize_t width) {
        const hsize_t dims[2] = {total_rows, width};
        const hid_t space = H5Screate_simple(width == 1 ? 1 : 2, dims, nullptr);
        const std::string path = "/realizations/" + name;
        const hid_t d =
            H5Dcreate2(f_.id(), path.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        H5Sclose(space);
        f_.check_id(d, "create " + path);
        H5Dclose(d);
    }

    /// Rows [first, first + data.size() / width) of dataset `name`.
    template <class T>
    void rows(const std::string& name, hid_t type, hsize_t first, hsize_t width,
              const std::vector<T>& data) {
        const hsize_t count = data.size() / width;
        if (count == 0) return;
        const std::string path = "/realizations/" + name;
        const hid_t d = f_.check_id(H5Dopen2(f_.id(), path.c_str(), H5P_DEFAULT), "open " + path);
        const hid_t fspace = H5Dget_space(d);
        const hsize_t start[2] = {first, 0}, cnt[2] = {count, width};
        H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, nullptr, cnt, nullptr);
        const hid_t mspace = H5Screate_simple(width == 1 ? 1 : 2, cnt, nullptr);
        const herr_t status = H5Dwrite(d, type, mspace, fspace, H5P_DEFAULT, data.data());
        H5Sclose(mspace);
        H5Sclose(fspace);
        H5Dclose(d);
        f_.check(status, "write " + path);
    }

    H5File& f_;
};

constexpr int kStateTag = 7301;  ///< a realization's state on its way to the checkpoint's writer
constexpr std::size_t kChunk = std::size_t{1} << 30;  ///< bytes per message (MPI counts are int)

/// A non-root rank's realization states to the root (which writes them): per state its size,
/// then its bytes in chunks of at most 1 GiB.
void send_states(const std::vector<RealizationState>& local, MPI_Comm comm) {
    for (const RealizationState& s : local) {
        const std::vector<std::uint8_t> bytes = pack(s);
        const std::uint64_t size = bytes.size();
        MPI_Send(&size, 1, MPI_UINT64_T, 0, kStateTag, comm);
        for (std::size_t at = 0; at < bytes.size(); at += kChunk)
            MPI_Send(bytes.data() + at, static_cast<int>(std::min(kChunk, bytes.size() - at)),
                     MPI_BYTE, 0, kStateTag, comm);
    }
}

RealizationState receive_state(int from, MPI_Comm comm) {
    std::uint64_t size = 0;
    MPI_Recv(&size, 1, MPI_UINT64_T, from, kStateTag, comm, MPI_STATUS_IGNORE);
    std::vector<std::uint8_t> bytes(size);
    for (std::size_t at = 0; at < bytes.size(); at += kChunk)
        MPI_Recv(bytes.data() + at, static_cast<int>(std::min(kChunk, bytes.size() - at)), MPI_BYTE,
                 from, kStateTag, comm, MPI_STATUS_IGNORE);
    return unpack(bytes);
}
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
    const RowCounts counts = count_rows(local);
    ensure_space(final_path, counts);
    // Every byte is written by the root, so that whatever fails is known to one rank that can
    // tell all the others (a failed collective MPI-IO write could not be agreed on).
    std::string failure;
    if (layout_.is_root())
        failure = write_on_root(final_path, sequence, local, counts, *header);
    else
        send_states(local, layout_.mpi().comm());
    broadcast_string(layout_.mpi().comm(), failure);
    if (!failure.empty())
        throw CheckpointWriteError(fmt::format("writing checkpoint {}: {}", sequence, failure));
    return final_path;
}

CheckpointWriter::RowCounts CheckpointWriter::count_rows(
    const std::vector<RealizationState>& local) const {
    std::array<double, 2> mine{0, 0}, total{0, 0};  // exact: counts far below 2^53
    for (const auto& s : local) {
        mine[0] += static_cast<double>(s.particles());
        mine[1] += static_cast<double>(s.pairs.size());
    }
    MPI_Reduce(mine.data(), total.data(), 2, MPI_DOUBLE, MPI_SUM, 0, layout_.mpi().comm());
    return {static_cast<hsize_t>(total[0]), static_cast<hsize_t>(total[1])};
}

std::string CheckpointWriter::write_on_root(const std::filesystem::path& final_path, long sequence,
                                            const std::vector<RealizationState>& local,
                                            const RowCounts& counts,
                                            const CheckpointHeader& header) const {
    std::filesystem::path tmp = final_path;
    tmp += ".tmp";
    std::string failure;  // the first; later steps are skipped, but every state is received
    auto attempt = [&](auto&& step) {
        if (!failure.empty()) return;
        try {
            step();
        } catch (const std::exception& e) {
            failure = e.what();
        }
    };
    std::optional<H5File> file;
    std::optional<RealizationTable> table;
    attempt([&] {
        file.emplace(H5File::create(tmp));
        table.emplace(*file, static_cast<hsize_t>(layout_.size()), counts.particles, counts.pairs);
    });
    const MPI_Comm comm = layout_.mpi().comm();
    RowStart at;
    for (int rank = 0; rank < layout_.mpi().size(); ++rank) {
        for (int j = 0; j < layout_.per_rank(); ++j) {
            const RealizationState received =
                rank == 0 ? RealizationState{} : receive_state(rank, comm);
            const RealizationState& s = rank == 0 ? local[static_cast<std::size_t>(j)] : received;
            EFDEM_ASSERT(s.index == static_cast<long>(at.realization));
            attempt([&] { table->write(s, at); });
            at.realization += 1;
            at.particle += s.particles();
            at.pair += s.pairs.size();
        }
        if (rank == 0 && settings_.debug_delay > 0)  // test hook: the job can be killed, or the
            // disk filled, while the file is open and the other ranks' rows are still to come
            std::this_thread::sleep_for(std::chrono::duration<double>(settings_.debug_delay));
    }
    attempt([&] { write_header(*file, sequence, header); });
    if (!failure.empty() && file) {
        // A file that failed for lack of space can fail to close too, and HDF5 then keeps it
        // half closed, which crashes the library's clean-up at exit: its rows are dropped
        // first, so that the close has the room they took.
        std::error_code ignored;
        std::filesystem::resize_file(tmp, 0, ignored);
    }
    table.reset();
    file.reset();
    attempt([&] {
        std::error_code ec;
        std::filesystem::rename(tmp, final_path, ec);
        if (ec)
            throw RuntimeFailure(fmt::format("cannot rename the checkpoint {} to {}: {}",
                                             tmp.string(), final_path.string(), ec.message()));
    });
    if (failure.empty()) {
        prune(final_path);
    } else {
        std::error_code ignored;
        std::filesystem::remove(tmp, ignored);  // a checkpoint that can never be whole
    }
    return failure;
}

void CheckpointWriter::ensure_space(const std::filesystem::path& path,
                                    const RowCounts& counts) const {
    // The space is looked at first, so that every rank gives up together, with nothing written,
    // when it is short.
    double verdict[2] = {1.0, 0.0};  // ok, bytes free
    if (layout_.is_root()) {
        // The rows (x, v, omega, force, torque, reference, walls, tag, species; pairs) ...
        double total =
            static_cast<double>(counts.particles) * (8 * sizeof(Vec3) + sizeof(dem::Tag) + 1) +
            static_cast<double>(counts.pairs) * sizeof(dem::PairHistoryRecord);
        std::error_code ec;  // ... and the output files stored with them
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

void CheckpointWriter::write_header(H5File& f, long sequence, const CheckpointHeader& state) const {
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
    if (std::isfinite(s.wall_seconds)) {  // absent: unknown (read as NaN)
        const std::vector<double> wall{s.wall_seconds};
        f.write("/driver/wall_seconds", std::span<const double>(wall), {1});
    }
    const std::vector<double> warmup_done{h.driver.warmup_done};
    f.write("/driver/warmup_done", std::span<const double>(warmup_done), {1});
    if (!h.driver.drift.empty())
        f.write("/driver/drift", std::span<const double>(h.driver.drift), {h.driver.drift.size()});
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
