#pragma once
/// \file
/// RunSettings: the run-level keys of a scene (everything that is not one realization's DEM).
///
/// | key                               | meaning                                          | default |
/// |-----------------------------------|--------------------------------------------------|---------|
/// | mode                              | `direct` or `cpi`                                | direct  |
/// | seed                              | master seed of every random stream               | 1       |
/// | ensemble.realizations_per_rank    | k: the ensemble has R = P x k realizations       | 1       |
/// | output.directory                  | where the run writes (relative to the scene's    | .       |
/// |                                   | folder when given in the scene, to the working   |         |
/// |                                   | directory when given on the command line)        |         |

#include <cstdint>
#include <filesystem>

#include "core/param_table.hpp"

namespace efdem::mpi_driver {

struct RunSettings {
    enum class Mode { direct, cpi } mode = Mode::direct;
    std::uint64_t seed = 1;
    int realizations_per_rank = 1;
    std::filesystem::path output_directory = ".";

    static RunSettings from_params(const Params& root);
};

}  // namespace efdem::mpi_driver
