#include "mpi_driver/parallel/mpi_session.hpp"

#include <cstdlib>
#include <utility>

#include <fmt/format.h>

#include "core/error.hpp"
#include "core/log.hpp"

namespace efdem::mpi_driver {

MpiComm::MpiComm(MPI_Comm comm) : comm_(comm) {
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
}

namespace {
std::function<void(const std::string&)>& last_words() {
    static std::function<void(const std::string&)> words;
    return words;
}
}  // namespace

void MpiComm::set_last_words(std::function<void(const std::string&)> words) {
    last_words() = std::move(words);
}

void MpiComm::abort(const std::string& message, int exit_code) const {
    log::rank_error("{}", message);
    if (auto words = std::exchange(last_words(), nullptr)) {  // once, even if it aborts again
        try {
            words(message);
        } catch (...) {
        }
    }
    MPI_Abort(comm_, exit_code);
    std::exit(exit_code);  // not reached
}

MpiSession::MpiSession(int* argc, char*** argv) {
    MPI_Init(argc, argv);
    // A failing MPI call ends the job (the default for MPI_COMM_WORLD, made explicit).
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_ARE_FATAL);
    world_.emplace(MPI_COMM_WORLD);
    // Messages name this rank from the start (the driver may change the level later).
    log::configure(world_->rank(), world_->size(), log::level());
}

MpiSession::~MpiSession() {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Finalize();
}

std::string MpiSession::launcher_mismatch() const {
    if (size() != 1) return {};
    // Variables that launchers of several MPI implementations and srun set per process. Not
    // SLURM_NTASKS: a batch script's own shell has it (the job's size), and a serial
    // `efdem --check` there (scripts/slurm_job.sh) is not a launcher mismatch.
    for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS",
                            "SLURM_STEP_NUM_TASKS"}) {
        const char* value = std::getenv(var);
        if (value && std::atoi(value) > 1)
            return fmt::format(
                "efdem was started as one of {} processes ({}={}) but its MPI library sees only "
                "this one: the launcher (mpirun/srun) belongs to a different MPI than the one "
                "efdem was built with ({}). Use that MPI's mpirun, or rebuild efdem.",
                value, var, value, MPI_VERSION == 3 ? "MPI-3" : "MPI");
    }
    return {};
}

}  // namespace efdem::mpi_driver
