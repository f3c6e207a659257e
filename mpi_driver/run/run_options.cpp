#include "mpi_driver/run/run_options.hpp"

#include <exception>
#include <string>

#include "core/error.hpp"

namespace efdem::mpi_driver {

RunOptions RunOptions::parse(int argc, const char* const* argv) {
    RunOptions o;
    const SourceLocation where{"<command line>", 0};
    for (int a = 1; a < argc; ++a) {
        const std::string arg = argv[a];
        if (arg == "--help" || arg == "-h")
            o.action = Action::help;
        else if (arg == "--version")
            o.action = Action::version;
        else if (arg == "--list-effects")
            o.action = Action::list_effects;
        else if (arg == "--check")
            o.action = Action::check;
        else if (arg == "--list-keys")
            o.action = Action::list_keys;
        else if (arg.rfind("--ranks=", 0) == 0) {
            const std::string v = arg.substr(8);
            std::size_t used = 0;
            long n = 0;
            try {
                n = std::stol(v, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (v.empty() || used != v.size() || n < 1 || n > 10000000)
                throw InputError(where,
                                 "--ranks='" + v +
                                     "': expected a whole number of ranks >= 1 (the ranks the "
                                     "checked run will have), e.g. --ranks=8");
            o.ranks = static_cast<int>(n);
        } else if (arg.rfind("--", 0) == 0)
            throw InputError(where, "unknown option '" + arg + "'; see efdem --help");
        else if (arg.rfind("restart=", 0) == 0) {
            o.restart = arg.substr(8);
            if (o.restart.empty())
                throw InputError(where, "restart= needs a checkpoint file: restart=FILE");
        } else if (arg.find('=') != std::string::npos)
            o.overrides.push_back(arg);
        else if (o.scene.empty())
            o.scene = arg;
        else
            throw InputError(where, "a second scene file '" + arg + "' was given after '" +
                                        o.scene + "'; give one scene and key=value overrides");
    }
    if ((o.action == Action::run || o.action == Action::check || o.action == Action::list_keys) &&
        o.scene.empty())
        throw InputError(where,
                         "no scene file given; usage: efdem [--check] SCENE [key=value ...]");
    if (o.ranks > 0 && o.action != Action::check && o.action != Action::list_keys)
        throw InputError(where,
                         "--ranks=N only goes with --check or --list-keys (a run has the ranks "
                         "mpirun gives it)");
    return o;
}

std::string RunOptions::usage() {
    return R"(efdem - equation-free (coarse projective) computation on MPI ensembles of DEM runs

usage:
  mpirun -np P efdem SCENE [key=value ...]    run the scene in its mode (key `mode`): direct (every
                                              realization simulated throughout), cpi (coarse
                                              projective integration), steady (the coarse steady
                                              state by Newton-GMRES and its eigenvalues) or
                                              continuation (the steady state along a parameter)
  mpirun -np P efdem SCENE restart=FILE [...] continue from a checkpoint
  efdem --check SCENE [key=value ...]         read the scene, build one realization, report the
                                              active effects and everything derived from the
                                              inputs, run zero steps
  efdem --check --ranks=N SCENE [...]         as --check, for a run on N ranks (what a batch
                                              script checks before it launches N)
  efdem --list-keys SCENE [key=value ...]     as --check, then every key the scene's set-up read
                                              (tab-separated, with a header: key, what it
                                              accepts, default or 'required', meaning); all
                                              keys: docs/scene_reference.md
  efdem --list-effects                        the effects a scene can list, with a summary
  efdem --version                             version, git hash, build
  efdem --help                                this text

key=value arguments override the scene file (e.g. seed=7 output.directory=runs/a).
restart=FILE continues the run saved in the checkpoint FILE (checkpoint.interval = N writes
one every N coarse steps, or N samples in direct mode); the scene must have the same physics
unless restart.allow_physics_change=true.
Exit codes: 0 success, 2 input error (nothing was computed), 3 failure while running,
4 stopped by a signal (SIGTERM, SIGINT, SIGUSR1) with a checkpoint to continue from (the
message names it and the restart= command).
Documentation: README.md, docs/ (effects in docs/effects/).
)";
}

}  // namespace efdem::mpi_driver
