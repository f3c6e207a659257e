#pragma once
/// \file
/// Which run a run file belongs to. A new run file gets a random `run_id` (root attribute); a
/// checkpoint stores the run file whole, so a restart can tell whether the run file it is about
/// to continue is the one its checkpoint came from. Run files written before the attribute
/// existed are told apart by what they all record: date (to the second), seed, mode, scene file
/// and overrides.

#include <cstdint>
#include <string>

namespace efdem::mpi_driver {

class H5File;

struct RunIdentity {
    std::string run_id;  ///< empty in run files older than the attribute
    std::string date;    ///< UTC start, "YYYY-MM-DDTHH:MM:SSZ"
    std::int64_t seed = 0;
    std::string mode;
    std::string scene_file;
    std::string overrides;

    /// The same run: equal run ids where both have one, else every recorded field equal.
    bool same_run(const RunIdentity& other) const;
    /// "run_id 3f2a..., started 2026-12-04T20:41:35Z, seed 7, mode cpi" for messages.
    std::string describe() const;
};

/// A fresh run id: 32 hexadecimal digits from the system's random device.
std::string new_run_id();

/// The identity recorded in a run file's root attributes (RuntimeFailure if it has none of
/// them: not a run file).
RunIdentity read_run_identity(const H5File& file);

}  // namespace efdem::mpi_driver
