#include "mpi_driver/checkpoint/checkpoint_settings.hpp"

namespace efdem::mpi_driver {

CheckpointSettings CheckpointSettings::from_params(const Params& root, const std::filesystem::path& output_directory) {
    CheckpointSettings s;
    const Params checkpoint = root.scope("checkpoint");
    s.interval = checkpoint.get_or<long>("interval", 0, Bounds::closed(0, 1000000000));
    s.keep = checkpoint.get_or<int>("keep", 2, Bounds::closed(1, 1000));
    s.directory = checkpoint.get_or_path("directory", output_directory);
    s.allow_physics_change = root.scope("restart").get_or<bool>("allow_physics_change", false);
    s.debug_delay = root.scope("debug").get_or<double>("checkpoint_delay", 0.0, Bounds::closed(0, 3600));
    return s;
}

}  // namespace efdem::mpi_driver
