#include "dem/contact/contact_history.hpp"

#include <algorithm>
#include <unordered_map>

#include "core/contracts.hpp"
#include "core/error.hpp"

namespace efdem::dem {

namespace {
bool active(const Vec3& v) {
    return v.x != 0.0 || v.y != 0.0 || v.z != 0.0;
}
}  // namespace

ContactHistory::ContactHistory(std::size_t n_particles) {
    for (auto& w : wall_) w.assign(n_particles, Vec3{});
}

void ContactHistory::attach(const NeighborList& list) {
    pair_.assign(list.size(), Vec3{});
}

void ContactHistory::stash(const NeighborList& list) {
    stash_.clear();
    if (pair_.size() != list.size()) return;  // no list yet
    const auto off = list.offsets();
    const auto ent = list.entries();
    for (std::size_t i = 0; i + 1 < off.size(); ++i)
        for (std::uint32_t k = off[i]; k < off[i + 1]; ++k)
            if (active(pair_[k]))
                stash_.push_back({static_cast<Index>(i), NeighborList::neighbor(ent[k]), pair_[k]});
}

void ContactHistory::restore(const NeighborList& list, std::span<const Index> new_to_old) {
    for (auto& w : wall_) {
        EFDEM_EXPECTS(w.size() == new_to_old.size());
        std::vector<Vec3> moved(w.size());
        for (std::size_t k = 0; k < w.size(); ++k) moved[k] = w[new_to_old[k]];
        w.swap(moved);
    }
    std::vector<Index> old_to_new(new_to_old.size());
    for (std::size_t k = 0; k < new_to_old.size(); ++k)
        old_to_new[new_to_old[k]] = static_cast<Index>(k);
    attach_stashed(list, old_to_new);
}

void ContactHistory::attach_stashed(const NeighborList& list, std::span<const Index> old_to_new) {
    pair_.assign(list.size(), Vec3{});
    if (stash_.empty()) return;
    // Bucket the stashed springs by the smaller new index, oriented smaller -> larger.
    const std::size_t n = old_to_new.size();
    std::vector<std::uint32_t> start(n + 1, 0);
    for (auto& s : stash_) {
        Index a = old_to_new[s.i], b = old_to_new[s.j];
        if (a > b) {
            std::swap(a, b);
            s.xi = -s.xi;
        }
        s.i = a;
        s.j = b;
        ++start[a + 1];
    }
    for (std::size_t i = 0; i < n; ++i) start[i + 1] += start[i];
    std::vector<Stashed> bucket(stash_.size());
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (const auto& s : stash_) bucket[fill[s.i]++] = s;

    const auto off = list.offsets();
    const auto ent = list.entries();
    for (std::size_t i = 0; i < n; ++i)
        for (std::uint32_t k = off[i]; k < off[i + 1]; ++k) {
            const Index j = NeighborList::neighbor(ent[k]);
            const Index lo = std::min(static_cast<Index>(i), j),
                        hi = std::max(static_cast<Index>(i), j);
            for (std::uint32_t b = start[lo]; b < start[lo + 1]; ++b)
                if (bucket[b].j == hi) {
                    pair_[k] = (lo == i) ? bucket[b].xi : -bucket[b].xi;
                    break;
                }
        }
    // A stashed spring whose pair is no longer listed had separated by more than the skin:
    // impossible for a touching pair between two builds, so such springs are simply dropped.
    stash_.clear();
}

std::size_t ContactHistory::active_pairs() const {
    return static_cast<std::size_t>(std::count_if(pair_.begin(), pair_.end(), active));
}

std::size_t ContactHistory::bytes() const {
    std::size_t b = pair_.capacity() * sizeof(Vec3) + stash_.capacity() * sizeof(Stashed);
    for (const auto& w : wall_) b += w.capacity() * sizeof(Vec3);
    return b;
}

std::vector<PairHistoryRecord> ContactHistory::export_pairs(const NeighborList& list,
                                                            const Particles& p) const {
    std::vector<PairHistoryRecord> out;
    const auto off = list.offsets();
    const auto ent = list.entries();
    const auto tag = p.tag();
    for (std::size_t i = 0; i + 1 < off.size(); ++i)
        for (std::uint32_t k = off[i]; k < off[i + 1]; ++k)
            if (active(pair_[k]))
                out.push_back({tag[i], tag[NeighborList::neighbor(ent[k])], pair_[k]});
    return out;
}

void ContactHistory::import_pairs(const NeighborList& list, const Particles& p,
                                  std::span<const PairHistoryRecord> records) {
    std::unordered_map<Tag, Index> index_of;
    index_of.reserve(p.size());
    const auto tag = p.tag();
    for (std::size_t i = 0; i < p.size(); ++i) index_of.emplace(tag[i], static_cast<Index>(i));
    stash_.clear();
    for (const auto& r : records) {
        const auto a = index_of.find(r.tag_i), b = index_of.find(r.tag_j);
        if (a == index_of.end() || b == index_of.end())
            throw RuntimeFailure("contact history names a particle tag that does not exist");
        stash_.push_back({a->second, b->second, r.xi});
    }
    std::vector<Index> identity(p.size());
    for (std::size_t i = 0; i < identity.size(); ++i) identity[i] = static_cast<Index>(i);
    attach_stashed(list, identity);
}

}  // namespace efdem::dem
