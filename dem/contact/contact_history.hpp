#pragma once
/// \file
/// ContactHistory: the tangential spring xi of every touching pair and of every particle
/// touching a wall (Cundall-Strack history, physics.md §5.1).
///
/// Exists only when an effect needs it (tangential = history): a scene without tangential
/// friction allocates none of this. Pair springs are stored parallel to the neighbour-list
/// entries; wall springs per particle and wall. Both survive neighbour-list rebuilds and the
/// spatial sort that comes with them: before a rebuild the active springs are set aside by
/// particle identity, afterwards they are re-attached to the new entries (with the sign flipped
/// when the pair is now listed under the other particle, since xi belongs to the pair i->j).
/// A zero spring means "no history"; a spring is zeroed when its contact opens.

#include <span>
#include <vector>

#include "core/vec3.hpp"
#include "dem/neighbor_list.hpp"
#include "dem/particles.hpp"

namespace efdem::dem {

/// One active pair spring identified by permanent particle tags (for checkpoints).
struct PairHistoryRecord {
    Tag tag_i;
    Tag tag_j;
    Vec3 xi;  ///< spring of the pair oriented i -> j
};

class ContactHistory {
  public:
    static constexpr int kFloor = 0;
    static constexpr int kLid = 1;
    static constexpr int kWalls = 2;

    explicit ContactHistory(std::size_t n_particles);

    std::span<Vec3> pairs() { return pair_; }
    std::span<const Vec3> pairs() const { return pair_; }
    std::span<Vec3> wall(int w) { return wall_[static_cast<std::size_t>(w)]; }
    std::span<const Vec3> wall(int w) const { return wall_[static_cast<std::size_t>(w)]; }

    /// Call before the neighbour list is rebuilt: sets the active pair springs aside.
    void stash(const NeighborList& list);
    /// Call after the rebuild: re-attaches the springs to the new entries.
    void restore(const NeighborList& list, std::span<const Index> new_to_old);
    /// Resizes the pair storage to the list (all zero), e.g. for a list built without history.
    void attach(const NeighborList& list);

    std::size_t active_pairs() const;
    std::size_t bytes() const;

    /// Active pair springs by tags, and the inverse (for checkpoints and restarts).
    std::vector<PairHistoryRecord> export_pairs(const NeighborList& list, const Particles& p) const;
    void import_pairs(const NeighborList& list, const Particles& p,
                      std::span<const PairHistoryRecord> records);

  private:
    struct Stashed {
        Index i, j;  ///< old indices
        Vec3 xi;
    };
    void attach_stashed(const NeighborList& list, std::span<const Index> old_to_new);

    std::vector<Vec3> pair_;
    std::vector<Vec3> wall_[kWalls];
    std::vector<Stashed> stash_;
};

}  // namespace efdem::dem
