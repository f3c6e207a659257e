#pragma once
/// \file
/// What the settling of a bed (dem/settling/) reports while it runs, to whoever builds the
/// realization (dem/realization_builder.hpp): here, beside the bed's settle protocol keys
/// (bed_builder.hpp), so that callers need not include dem/settling/.

#include <functional>

namespace efdem::dem {

/// Where the settling of one realization stands (times in sqrt(d_p/g) from its start).
struct SettlingProgress {
    enum class Stage { free_fall, damped, relaxing, done };
    long realization = 0;
    Stage stage = Stage::free_fall;
    double time = 0;       ///< settling time so far
    long steps = 0;        ///< time steps so far
    double stage_end = 0;  ///< when the stage ends (relaxing: at the latest, bed.settle.max_time)
    double ke_per_particle = 0;  ///< translational kinetic energy per particle
    double ke_threshold =
        0;  ///< the criterion of the relaxing stage: settled when ke_per_particle < it
};

/// "free fall", "damped", "relaxing", "done".
inline const char* to_string(SettlingProgress::Stage stage) {
    switch (stage) {
        case SettlingProgress::Stage::free_fall:
            return "free fall";
        case SettlingProgress::Stage::damped:
            return "damped";
        case SettlingProgress::Stage::relaxing:
            return "relaxing";
        case SettlingProgress::Stage::done:
            return "done";
    }
    return "?";
}

/// Receives SettlingProgress reports (may be empty: no reports).
using SettlingReport = std::function<void(const SettlingProgress&)>;

}  // namespace efdem::dem
