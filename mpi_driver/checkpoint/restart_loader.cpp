#include "mpi_driver/checkpoint/restart_loader.hpp"

#include <exception>
#include <fstream>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/log.hpp"
#if EFDEM_HAVE_HDF5
#include "mpi_driver/checkpoint/checkpoint_reader.hpp"
#endif
#include "mpi_driver/checkpoint/restart_check.hpp"

namespace efdem::mpi_driver {

namespace {
/// Runs `stage`, turning its exception into an exit code and message, then agrees.
template <class F>
Agreement agreed_stage(const MpiComm& mpi, F&& stage) {
    int code = kExitOk;
    std::string message;
    try {
        stage();
    } catch (const InputError& e) {
        code = kExitInputError;
        message = e.what();
    } catch (const std::exception& e) {
        code = kExitInputError;
        message = std::string("restart: ") + e.what();
    }
    return agree_on_failure(mpi.comm(), code, message);
}
}  // namespace

Agreement load_restart(const MpiComm& mpi, const std::filesystem::path& path,
                       const std::string& parameters, int per_rank, bool allow_physics_change,
                       RestartData& out) {
    out.path = path;
#if !EFDEM_HAVE_HDF5
    (void)parameters;
    (void)per_rank;
    (void)allow_physics_change;
    return agreed_stage(mpi, [&] {
        throw InputError(SourceLocation{path.string(), 0},
                         "checkpoints need HDF5; this efdem was built without it");
    });
#else
    Agreement a = agreed_stage(mpi, [&] {
        if (!mpi.is_root()) return;
        out.header = read_checkpoint_header(path);
        const std::string warning =
            check_restart(path, out.header, parameters, static_cast<long>(mpi.size()) * per_rank,
                          allow_physics_change, read_checkpoint_time(path));
        if (!warning.empty()) log::warn("{}", warning);
    });
    if (a.exit_code != kExitOk) return a;
    a = agreed_stage(mpi, [&] {
        const SourceLocation where{path.string(), 0};
        out.local =
            read_checkpoint_realizations(path, static_cast<long>(mpi.rank()) * per_rank, per_rank);
        for (int j = 0; j < per_rank; ++j)
            if (out.local[j].index != static_cast<long>(mpi.rank()) * per_rank + j)
                throw InputError(where, fmt::format("checkpoint row {} holds realization {}",
                                                    mpi.rank() * per_rank + j, out.local[j].index));
    });
    if (a.exit_code != kExitOk) return a;
    // The counters every rank keeps (samples taken drives the per-realization outputs).
    double counters[3] = {static_cast<double>(out.header.stepper.samples_taken),
                          out.header.stepper.micro_time, out.header.stepper.particle_steps};
    MPI_Bcast(counters, 3, MPI_DOUBLE, 0, mpi.comm());
    out.header.stepper.samples_taken = std::lround(counters[0]);
    out.header.stepper.micro_time = counters[1];
    out.header.stepper.particle_steps = counters[2];
    // Which realizations are in the ensemble (dropped ones are not restored or advanced), and
    // the failures survived so far.
    long failures_and_size[2] = {out.header.stepper.failures,
                                 static_cast<long>(out.header.stepper.active.size())};
    MPI_Bcast(failures_and_size, 2, MPI_LONG, 0, mpi.comm());
    out.header.stepper.failures = failures_and_size[0];
    out.header.stepper.active.resize(static_cast<std::size_t>(failures_and_size[1]));
    if (failures_and_size[1] > 0)
        MPI_Bcast(out.header.stepper.active.data(), static_cast<int>(failures_and_size[1]),
                  MPI_INT64_T, 0, mpi.comm());
    return a;
#endif
}

void restore_outputs(const CheckpointHeader& header, const std::filesystem::path& directory,
                     const std::string& prefix) {
    for (const auto& o : header.outputs) {
        if (o.name.empty() || o.name.find('/') != std::string::npos ||
            o.name.find("..") != std::string::npos)
            throw RuntimeFailure(
                fmt::format("restart: the checkpoint names an output file '{}'", o.name));
        const auto p = directory / (prefix + o.name);
        std::ofstream f(p, std::ios::binary | std::ios::trunc);
        f.write(o.bytes.data(), static_cast<std::streamsize>(o.bytes.size()));
        if (!f)
            throw RuntimeFailure(
                fmt::format("restart: cannot write the output file {}", p.string()));
    }
}

}  // namespace efdem::mpi_driver
