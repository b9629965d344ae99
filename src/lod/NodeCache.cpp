#include "lod/NodeCache.h"

#include <type_traits>
#include <utility>
#include <vector>

#include "core/Error.h"

namespace subscan::lod {

std::size_t memoryBytes(const PointCloud& cloud) {
    const auto bytes = [](const auto& values) {
        return values.size() * sizeof(typename std::decay_t<decltype(values)>::value_type);
    };
    return sizeof(PointCloud) + bytes(cloud.positions) + bytes(cloud.colors) +
           bytes(cloud.normals) + bytes(cloud.intensities) + bytes(cloud.classifications) +
           bytes(cloud.triangles);
}

CachedNodeSource::CachedNodeSource(std::shared_ptr<const NodeSource> source,
                                   std::uint64_t byteBudget)
    : source_(std::move(source)), byteBudget_(byteBudget) {
    info_ = source_->info();
    setNodes(std::vector<StreamedNode>(source_->nodes().begin(), source_->nodes().end()));
}

PointCloud CachedNodeSource::load(std::size_t index) const {
    std::shared_ptr<const PointCloud> kept;  // outlives an eviction while it is copied
    {
        const std::lock_guard lock(mutex_);
        if (const auto found = entries_.find(index); found != entries_.end()) {
            Entry& entry = found->second;
            recency_.splice(recency_.begin(), recency_, entry.recency);
            ++usage_.hits;
            if (!entry.cloud) {
                throw Error(entry.failure);
            }
            kept = entry.cloud;
        } else {
            ++usage_.misses;
        }
    }
    if (kept) {
        return *kept;
    }
    Entry entry;
    try {
        auto cloud = std::make_shared<const PointCloud>(source_->load(index));
        entry.bytes = memoryBytes(*cloud);
        entry.cloud = std::move(cloud);
    } catch (const Error& error) {
        // Remembered: a broken tile stays broken while the source is open.
        entry.failure = error.what();
        entry.bytes = sizeof(Entry) + entry.failure.size();
        const std::lock_guard lock(mutex_);
        keep(index, std::move(entry));
        throw;
    }
    kept = entry.cloud;
    {
        const std::lock_guard lock(mutex_);
        keep(index, std::move(entry));
    }
    return *kept;
}

void CachedNodeSource::keep(std::size_t index, Entry entry) const {
    if (entry.bytes > byteBudget_ || entries_.contains(index)) {
        return;  // too large to keep, or kept by another thread meanwhile
    }
    const auto kept = entries_.emplace(index, std::move(entry)).first;
    try {
        recency_.push_front(index);
    } catch (...) {
        entries_.erase(kept);  // out of memory: not kept, and no recency without its entry
        throw;
    }
    kept->second.recency = recency_.begin();
    usage_.bytes += kept->second.bytes;
    ++usage_.nodes;
    while (usage_.bytes > byteBudget_) {
        const std::size_t oldest = recency_.back();
        recency_.pop_back();
        const auto found = entries_.find(oldest);
        usage_.bytes -= found->second.bytes;
        entries_.erase(found);
        --usage_.nodes;
    }
}

CachedNodeSource::Usage CachedNodeSource::usage() const {
    const std::lock_guard lock(mutex_);
    return usage_;
}

}  // namespace subscan::lod
