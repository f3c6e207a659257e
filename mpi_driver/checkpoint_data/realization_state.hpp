#pragma once
/// \file
/// RealizationState: everything one DEM realization needs to continue bit for bit, as plain
/// arrays in the current storage order (what a checkpoint holds per realization).
///
/// Forces and torques are saved rather than recomputed: velocity Verlet starts a step with the
/// forces of the previous one, which were evaluated at half-step velocities (damping, drag), so
/// recomputing them from the full-step velocities would not give the same numbers.

#include <cstdint>
#include <cstring>
#include <vector>

#include "dem/contact/contact_history.hpp"

namespace efdem::mpi_driver {

struct RealizationState {
    long index = -1;  ///< global realization index
    double time = 0;  ///< simulated time
    long step = 0;    ///< DEM step counter
    std::vector<Vec3> x, v, omega, force, torque;
    std::vector<dem::Tag> tag;
    std::vector<std::uint8_t> species;
    std::vector<Vec3> reference;                          ///< positions of the last list build
    std::vector<dem::PairHistoryRecord> pairs;            ///< active pair springs by tags
    std::vector<Vec3> wall[dem::ContactHistory::kWalls];  ///< per particle (empty: none)
    /// Consecutive sample intervals at whose end the realization was still (DemRealization:
    /// its rest judgement); checkpoints written before it hold none (0).
    long still_samples = 0;

    std::size_t particles() const { return x.size(); }
    /// FNV-1a over every array and scalar above: a checkpoint stores it, a restart verifies it.
    std::uint64_t checksum() const;
};

/// FNV-1a 64 of raw bytes, continuing from `h`.
/// The state as bytes and back (to send a realization's state to another rank); the layout is
/// this build's, not a file format.
std::vector<std::uint8_t> pack(const RealizationState& s);
RealizationState unpack(const std::vector<std::uint8_t>& bytes);

std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t h = 0xcbf29ce484222325ULL);

/// FNV-1a of an array's length and contents (trivially copyable elements).
template <class T>
std::uint64_t fnv1a_array(const std::vector<T>& a, std::uint64_t h) {
    const std::uint64_t n = a.size();
    h = fnv1a(&n, sizeof n, h);
    return a.empty() ? h : fnv1a(a.data(), a.size() * sizeof(T), h);
}

/// HDF5 has no unsigned 64-bit type we use: checksums and random states are stored bit-cast.
inline std::int64_t to_stored(std::uint64_t u) {
    std::int64_t i = 0;
    std::memcpy(&i, &u, sizeof i);
    return i;
}
inline std::uint64_t from_stored(std::int64_t i) {
    std::uint64_t u = 0;
    std::memcpy(&u, &i, sizeof u);
    return u;
}

}  // namespace efdem::mpi_driver
