// efdem: the driver. Start MPI and the logger, read the command line, answer what needs no run,
// set up collectively (setup.hpp), load a restart, launch the run (ensemble_run.hpp) and return
// its exit code: 0 done, 2 input error, 3 failure, 4 stopped with a checkpoint (core/error.hpp).
#include <optional>

#include "core/error.hpp"
#include "core/log.hpp"
#include "mpi_driver/checkpoint/restart_check.hpp"
#include "mpi_driver/checkpoint/restart_loader.hpp"
#include "mpi_driver/parallel/mpi_session.hpp"
#include "mpi_driver/parallel/stop_signal.hpp"
#include "mpi_driver/run/check_report.hpp"
#include "mpi_driver/run/ensemble_run.hpp"
#include "mpi_driver/run/listings.hpp"
#include "mpi_driver/run/run_options.hpp"
#include "mpi_driver/run/setup.hpp"

using namespace efdem;
using namespace efdem::mpi_driver;

namespace {
/// The root prints the agreed message of a failed stage; every rank returns its exit code.
int failed(const MpiSession& mpi, const Agreement& agreed) {
    if (!mpi.is_root()) return agreed.exit_code;
    if (agreed.exit_code == kExitInterrupted)  // a stop asked for, not an error
        log::notice("{}", agreed.message);
    else
        log::error("{}", agreed.message);
    return agreed.exit_code;
}
}  // namespace

int main(int argc, char** argv) {
    MpiSession mpi(&argc, &argv);
    SetupWall wall;
    log::configure(mpi.rank(), mpi.size(), log::Level::info);
    // From here on a stop signal is held until the run reaches a safe point (stop_signal.hpp).
    install_stop_signal_handlers();

    RunOptions options;
    try {
        options = RunOptions::parse(argc, argv);
    } catch (const InputError& e) {
        if (mpi.is_root()) log::error("{}", e.what());
        return kExitInputError;
    }
    if (print_listing(options.action)) return kExitOk;
    if (const std::string mismatch = mpi.launcher_mismatch(); !mismatch.empty()) {
        log::error("{}", mismatch);
        return kExitInputError;
    }

    SetUp setup;
    if (const Agreement agreed = set_up(mpi, options, wall, setup); agreed.exit_code != kExitOk)
        return failed(mpi, agreed);
    if (setup.check) {
        if (options.action == RunOptions::Action::list_keys)
            print_keys(*setup.table);
        else if (mpi.is_root())  // the report is the root's (log::output prints only there)
            log::output(
                check_report(*setup.table, *setup.settings, setup.systems.front(), setup.ranks));
        return kExitOk;
    }
    std::optional<RestartData> restart;
    if (!options.restart.empty()) {
        restart.emplace();
        const Agreement loaded =
            load_restart(mpi.world(), options.restart, parameter_lines(*setup.table),
                         setup.settings->realizations_per_rank,
                         setup.settings->checkpoint.allow_physics_change, *restart);
        if (loaded.exit_code != kExitOk) return failed(mpi, loaded);
    }
    return run_ensemble(mpi, *setup.table, *setup.settings, std::move(setup.systems),
                        restart ? &*restart : nullptr, wall);
}
