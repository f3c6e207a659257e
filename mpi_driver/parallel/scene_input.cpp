#include "mpi_driver/parallel/scene_input.hpp"

#include <filesystem>

#include "mpi_driver/parallel/mpi_broadcast.hpp"

namespace efdem::mpi_driver {

ParamTable read_scene(const MpiSession& mpi, const std::string& path,
                      const std::vector<std::string>& overrides) {
    std::string text, problem;
    int ok = 1;
    if (mpi.is_root()) {
        try {
            text = ParamTable::read_text_file(path);
        } catch (const InputError& e) {
            ok = 0;
            problem = e.problem();
        }
    }
    MPI_Bcast(&ok, 1, MPI_INT, 0, mpi.comm());
    if (!ok) {
        broadcast_string(mpi.comm(), problem);
        throw InputError({path, 0}, problem);
    }
    broadcast_string(mpi.comm(), text);
    const std::filesystem::path p(path);
    ParamTable table = ParamTable::from_text(text, path, p.parent_path());
    for (const auto& o : overrides) table.add_override(o);
    return table;
}

}  // namespace efdem::mpi_driver
