#include "mpi_driver/output/run_identity.hpp"

#include <random>

#include <fmt/format.h>

#include "core/error.hpp"
#include "mpi_driver/output/h5_file.hpp"

namespace efdem::mpi_driver {

bool RunIdentity::same_run(const RunIdentity& other) const {
    if (!run_id.empty() && !other.run_id.empty()) return run_id == other.run_id;
    return date == other.date && seed == other.seed && mode == other.mode &&
           scene_file == other.scene_file && overrides == other.overrides;
}

std::string RunIdentity::describe() const {
    return fmt::format("run_id {}, started {}, seed {}, mode {}, scene {}",
                       run_id.empty() ? std::string("(none: an older run file)") : run_id, date,
                       seed, mode, scene_file);
}

std::string new_run_id() {
    std::random_device device;
    std::string id;
    for (int i = 0; i < 4; ++i) id += fmt::format("{:08x}", device());
    return id;
}

RunIdentity read_run_identity(const H5File& file) {
    if (!file.has_attribute("/", "date") || !file.has_attribute("/", "mode"))
        throw RuntimeFailure(
            fmt::format("{} is not an efdem run file (no date or mode attribute)", file.path()));
    RunIdentity id;
    if (file.has_attribute("/", "run_id")) id.run_id = file.attribute_text("/", "run_id");
    id.date = file.attribute_text("/", "date");
    id.mode = file.attribute_text("/", "mode");
    if (file.has_attribute("/", "seed")) id.seed = file.attribute_integer("/", "seed");
    if (file.has_attribute("/", "scene_file"))
        id.scene_file = file.attribute_text("/", "scene_file");
    if (file.has_attribute("/", "overrides")) id.overrides = file.attribute_text("/", "overrides");
    return id;
}

}  // namespace efdem::mpi_driver
