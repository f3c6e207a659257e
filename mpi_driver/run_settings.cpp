#include "mpi_driver/run_settings.hpp"

namespace efdem::mpi_driver {

RunSettings RunSettings::from_params(const Params& root) {
    RunSettings s;
    s.mode = root.get_or_choice("mode", "direct", {"direct", "cpi"}) == "cpi" ? Mode::cpi : Mode::direct;
    s.seed = root.get_or<std::uint64_t>("seed", 1);
    s.realizations_per_rank =
        root.scope("ensemble").get_or<int>("realizations_per_rank", 1, Bounds::closed(1, 4096));
    s.output_directory = root.scope("output").get_or_path("directory", ".");
    return s;
}

}  // namespace efdem::mpi_driver
