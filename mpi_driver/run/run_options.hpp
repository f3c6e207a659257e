#pragma once
/// \file
/// RunOptions: the command line of `efdem`.
///
///   efdem [--help] [--version] [--list-effects]
///   mpirun -np P efdem [--check] SCENE [key=value ...]
///
/// `key=value` arguments override the scene's values (they win over the file).

#include <string>
#include <vector>

namespace efdem::mpi_driver {

struct RunOptions {
    enum class Action { run, check, list_keys, help, version, list_effects } action = Action::run;
    std::string scene;                   ///< path of the scene file
    std::vector<std::string> overrides;  ///< "key=value"
    std::string restart;                 ///< `restart=FILE`: the checkpoint to continue from
    /// `--ranks=N` (with --check or --list-keys): check the scene as for a run on N ranks (a
    /// batch script checks serially before it launches N); 0: the ranks this process runs on.
    int ranks = 0;

    /// Parses argv; InputError (location "<command line>") for anything it does not understand.
    static RunOptions parse(int argc, const char* const* argv);
    static std::string usage();
};

}  // namespace efdem::mpi_driver
