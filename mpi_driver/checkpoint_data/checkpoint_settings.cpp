#include "mpi_driver/checkpoint_data/checkpoint_settings.hpp"

#include <fmt/format.h>

namespace efdem::mpi_driver {

CheckpointSettings CheckpointSettings::from_params(const Params& root,
                                                   const std::filesystem::path& output_directory) {
    CheckpointSettings s;
    const Params checkpoint = root.scope("checkpoint");
    s.interval = checkpoint.get_or<long>("interval", 0, Bounds::closed(0, 1000000000));
    s.keep = checkpoint.get_or<int>("keep", 2, Bounds::closed(1, 1000));
    s.directory = checkpoint.get_or_path("directory", output_directory);
    if (s.directory.string().size() > 3000)
        checkpoint.fail("directory",
                        fmt::format("is {} characters long", s.directory.string().size()),
                        "a path of at most 3000 characters");
    s.allow_physics_change = root.scope("restart").get_or<bool>("allow_physics_change", false);
    s.debug_delay =
        root.scope("debug").get_or<double>("checkpoint_delay", 0.0, Bounds::closed(0, 3600));
    return s;
}

}  // namespace efdem::mpi_driver
