#pragma once

#include <cstddef>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "lod/NodeSource.h"

namespace subscan::lod {

/// Bytes a decoded node takes in memory: its attribute arrays' elements (not their spare
/// capacity, which a loaded node does not have, nor the cache's own bookkeeping, a few dozen
/// bytes a node: the budget is the points').
std::size_t memoryBytes(const PointCloud& cloud);

/// A node source that keeps the nodes it decoded, the least recently used leaving first once
/// they take more than a byte budget: a viewer that moves back and forth over a survey decodes
/// each node once, and its memory stays bounded whatever the survey's size. A node that could
/// not be read is remembered as such (its sentence given again) and not read again.
/// Safe from several threads at once; two threads asking for the same missing node may both
/// decode it (the second result is dropped).
class CachedNodeSource final : public NodeSource {
  public:
    CachedNodeSource(std::shared_ptr<const NodeSource> source, std::uint64_t byteBudget);

    PointCloud load(std::size_t index) const override;

    struct Usage {
        std::uint64_t bytes = 0;   // held now, at most the budget
        std::size_t nodes = 0;     // held now
        std::uint64_t hits = 0;    // loads answered from memory
        std::uint64_t misses = 0;  // loads that read the source
    };
    Usage usage() const;
    std::uint64_t byteBudget() const { return byteBudget_; }

  private:
    struct Entry {
        std::shared_ptr<const PointCloud> cloud;  // null: the node could not be read
        std::string failure;
        std::size_t bytes = 0;
        std::list<std::size_t>::iterator recency;
    };
    /// Keeps `entry` for node `index` as the most recently used, then evicts the least
    /// recently used entries until the budget holds. Called with mutex_ held.
    void keep(std::size_t index, Entry entry) const;

    std::shared_ptr<const NodeSource> source_;
    std::uint64_t byteBudget_;
    mutable std::mutex mutex_;
    mutable std::unordered_map<std::size_t, Entry> entries_;
    mutable std::list<std::size_t> recency_;  // most recently used first
    mutable Usage usage_;
};

}  // namespace subscan::lod
