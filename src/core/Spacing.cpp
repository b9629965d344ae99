#include "core/Spacing.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <iterator>
#include <limits>
#include <span>
#include <thread>
#include <vector>

#include "core/KdTree.h"

namespace subscan {

namespace {

constexpr float kUnknown = std::numeric_limits<float>::infinity();

float squaredDistance(const glm::vec3& a, const glm::vec3& b) {
    const glm::vec3 d = a - b;
    return d.x * d.x + d.y * d.y + d.z * d.z;
}

/// The squared distance from each query to its nearest non-coincident point of `points`, or
/// kUnknown. Scans often repeat points (overlapping range images, quantised coordinates), so
/// the search looks a few neighbours deep for the first one at a non-zero distance.
void nearestByKdTree(const std::vector<glm::vec3>& points, const std::vector<glm::vec3>& queries,
                     std::span<const std::uint32_t> which, std::vector<float>& nearest) {
    const PositionsAdaptor adaptor{points};
    const KdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    constexpr std::size_t kCandidates = 8;
    std::array<std::uint32_t, kCandidates> indices{};
    std::array<float, kCandidates> squaredDistances{};
    for (const std::uint32_t q : which) {
        const std::size_t found =
            tree.knnSearch(&queries[q].x, kCandidates, indices.data(), squaredDistances.data());
        for (std::size_t k = 0; k < found; ++k) {
            if (squaredDistances[k] > 0.0f) {
                nearest[q] = std::min(nearest[q], squaredDistances[k]);
                break;
            }
        }
    }
}

/// A hash grid of cubic cells holding, for each cell, the queries in it or in one of its 26
/// neighbours: a point then meets exactly the queries whose nearest neighbour it could be
/// among those within one cell size. Cell coordinates are packed 21 bits each; coordinates
/// that wrap only make unrelated cells share a slot, which costs distance tests, not results.
class QueryNeighbourhoods {
  public:
    QueryNeighbourhoods(const std::vector<glm::vec3>& queries,
                        std::span<const std::uint32_t> active, float cellSize)
        : corner_(queries[active.front()]), inverseCell_(1.0f / cellSize) {
        std::vector<std::pair<std::uint64_t, std::uint32_t>> entries;
        entries.reserve(active.size() * 27);
        for (const std::uint32_t q : active) {
            const std::array<std::int64_t, 3> cell = cellOf(queries[q]);
            for (int dx = -1; dx <= 1; ++dx) {
                for (int dy = -1; dy <= 1; ++dy) {
                    for (int dz = -1; dz <= 1; ++dz) {
                        entries.emplace_back(key({cell[0] + dx, cell[1] + dy, cell[2] + dz}), q);
                    }
                }
            }
        }
        std::sort(entries.begin(), entries.end());
        const std::size_t slots = std::bit_ceil(std::max<std::size_t>(entries.size() * 3 / 2, 16));
        slotBits_ = std::countr_zero(slots);
        // At least eight bits per cell, so that at most one point in eight of those outside
        // every neighbourhood gets past the filter; few cells, a filter in the L1 cache.
        filterBits_ = std::clamp(std::countr_zero(std::bit_ceil(slots * 8)), 12, 24);
        filter_.assign((std::size_t{1} << filterBits_) / 64, 0);
        slots_.assign(slots, Slot{});
        queries_.reserve(entries.size());
        for (std::size_t begin = 0; begin < entries.size();) {
            std::size_t end = begin;
            while (end < entries.size() && entries[end].first == entries[begin].first) {
                queries_.push_back(entries[end++].second);
            }
            std::size_t slot = hash(entries[begin].first);
            while (slots_[slot].key != kEmpty) {
                slot = (slot + 1) & (slots_.size() - 1);
            }
            slots_[slot] = {entries[begin].first, static_cast<std::uint32_t>(begin),
                            static_cast<std::uint32_t>(end)};
            const std::size_t bit = filterBit(entries[begin].first);
            filter_[bit / 64] |= std::uint64_t{1} << (bit % 64);
            begin = end;
        }
    }

    std::span<const std::uint32_t> near(const glm::vec3& point) const {
        const std::uint64_t wanted = key(cellOf(point));
        // Most points lie in no query's neighbourhood: a bit set small enough for the cache
        // turns them away before the table (cache misses) is probed.
        const std::size_t bit = filterBit(wanted);
        if ((filter_[bit / 64] >> (bit % 64) & 1) == 0) {
            return {};
        }
        for (std::size_t slot = hash(wanted);; slot = (slot + 1) & (slots_.size() - 1)) {
            const Slot& candidate = slots_[slot];
            if (candidate.key == wanted) {
                return {queries_.data() + candidate.begin, candidate.end - candidate.begin};
            }
            if (candidate.key == kEmpty) {
                return {};
            }
        }
    }

  private:
    static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // packed keys use 63 bits
    struct Slot {
        std::uint64_t key = kEmpty;
        std::uint32_t begin = 0;
        std::uint32_t end = 0;
    };

    std::array<std::int64_t, 3> cellOf(const glm::vec3& point) const {
        // Clamped so that far outliers at a tiny cell size stay a defined conversion.
        constexpr float kLimit = 1.0e15f;
        std::array<std::int64_t, 3> cell{};
        for (int axis = 0; axis < 3; ++axis) {
            const float scaled = (point[axis] - corner_[axis]) * inverseCell_;
            cell[static_cast<std::size_t>(axis)] =
                std::isnan(scaled)
                    ? 0
                    : static_cast<std::int64_t>(std::floor(std::clamp(scaled, -kLimit, kLimit)));
        }
        return cell;
    }
    static std::uint64_t key(const std::array<std::int64_t, 3>& cell) {
        constexpr std::uint64_t kMask = (std::uint64_t{1} << 21) - 1;
        return (static_cast<std::uint64_t>(cell[0]) & kMask) |
               (static_cast<std::uint64_t>(cell[1]) & kMask) << 21 |
               (static_cast<std::uint64_t>(cell[2]) & kMask) << 42;
    }
    std::size_t hash(std::uint64_t packed) const {
        return static_cast<std::size_t>((packed * 0x9E3779B97F4A7C15ull) >> (64 - slotBits_));
    }
    std::size_t filterBit(std::uint64_t packed) const {
        return static_cast<std::size_t>((packed * 0xD6E8FEB86659FD93ull) >> (64 - filterBits_));
    }

    glm::vec3 corner_;
    float inverseCell_;
    int slotBits_ = 0;
    std::vector<Slot> slots_;
    std::vector<std::uint32_t> queries_;
    int filterBits_ = 0;
    std::vector<std::uint64_t> filter_;
};

/// Lowers nearest[q] to the squared distance of every non-coincident point within one cell of
/// each active query: one pass over the points, split across the machine's cores.
void nearestByGrid(const std::vector<glm::vec3>& points, const std::vector<glm::vec3>& queries,
                   std::span<const std::uint32_t> active, float cellSize,
                   std::vector<float>& nearest) {
    const QueryNeighbourhoods grid(queries, active, cellSize);
    const std::size_t threads = std::clamp<std::size_t>(std::thread::hardware_concurrency(), 1, 16);
    std::vector<std::vector<float>> perThread(threads, nearest);
    const auto scan = [&](std::size_t thread) {
        std::vector<float>& own = perThread[thread];
        const std::size_t first = thread * points.size() / threads;
        const std::size_t last = (thread + 1) * points.size() / threads;
        for (std::size_t i = first; i < last; ++i) {
            for (const std::uint32_t q : grid.near(points[i])) {
                const float distance = squaredDistance(points[i], queries[q]);
                if (distance > 0.0f && distance < own[q]) {
                    own[q] = distance;
                }
            }
        }
    };
    std::vector<std::jthread> workers;
    for (std::size_t thread = 1; thread < threads; ++thread) {
        workers.emplace_back(scan, thread);
    }
    scan(0);
    workers.clear();
    for (const std::vector<float>& own : perThread) {
        for (const std::uint32_t q : active) {
            nearest[q] = std::min(nearest[q], own[q]);
        }
    }
}

/// The squared distances of sampledNearestDistances.
std::vector<float> sampledNearestSquared(const PointCloud& cloud, std::size_t maxSamples) {
    const std::size_t count = cloud.size();
    if (count == 0 || maxSamples == 0) {
        return {};
    }
    const std::size_t samples = std::min(count, maxSamples);
    std::vector<glm::vec3> queries(samples);
    std::vector<std::uint32_t> all(samples);
    for (std::size_t s = 0; s < samples; ++s) {
        queries[s] = cloud.positions[s * count / samples];
        all[s] = static_cast<std::uint32_t>(s);
    }
    std::vector<float> nearest(samples, kUnknown);
    // Up to about a million points a k-d tree over the cloud is built in a fraction of a
    // second; over ten million it takes seconds, where a pass over them with a hash grid of
    // the queries takes tens of milliseconds.
    constexpr std::size_t kGridAbovePointsPerQuery = 32;
    if (count <= kGridAbovePointsPerQuery * samples) {
        nearestByKdTree(cloud.positions, queries, all, nearest);
        return nearest;
    }
    // The queries' nearest neighbours among themselves bound each one's in the cloud.
    nearestByKdTree(queries, queries, all, nearest);
    std::vector<float> bounds;
    for (const float bound : nearest) {
        if (bound < kUnknown) {
            bounds.push_back(bound);
        }
    }
    if (bounds.empty()) {
        nearestByKdTree(cloud.positions, queries, all, nearest);
        return nearest;
    }
    // The queries are r = samples / count as dense as the cloud, so the cloud's neighbours are
    // nearer by r^(1/d) on a d-dimensional shape: cells of 2 r^(1/3) times the queries' median
    // settle almost every query of a surface or a volume in the first pass (and of a line, with
    // larger cells than it needs). A query is settled once the nearest neighbour found lies
    // within one cell, as every point that close has been tested; the others (isolated points)
    // go round again with cells four times larger.
    std::nth_element(bounds.begin(), bounds.begin() + bounds.size() / 2, bounds.end());
    const float ratio = static_cast<float>(samples) / static_cast<float>(count);
    float cellSize = std::sqrt(bounds[bounds.size() / 2]) * 2.0f * std::cbrt(ratio);
    std::vector<std::uint32_t> unsettled = all;
    constexpr int kPasses = 8;
    for (int pass = 0; pass < kPasses && !unsettled.empty() && cellSize > 0.0f; ++pass) {
        nearestByGrid(cloud.positions, queries, unsettled, cellSize, nearest);
        std::erase_if(unsettled,
                      [&](std::uint32_t q) { return nearest[q] <= cellSize * cellSize; });
        cellSize *= 4.0f;
    }
    if (!unsettled.empty()) {
        nearestByKdTree(cloud.positions, queries, unsettled, nearest);
    }
    return nearest;
}

}  // namespace

SpacingSample sampleSpacing(const PointCloud& cloud, std::size_t maxSamples) {
    SpacingSample sample;
    const std::vector<float> squared = sampledNearestSquared(cloud, maxSamples);
    // h from the squared distances (sqrt in double), as it always was: the same h to the bit.
    std::vector<float> known;
    known.reserve(squared.size());
    std::copy_if(squared.begin(), squared.end(), std::back_inserter(known),
                 [](float distance) { return distance != kUnknown; });
    if (!known.empty()) {
        const auto middle = known.begin() + static_cast<std::ptrdiff_t>(known.size() / 2);
        std::nth_element(known.begin(), middle, known.end());
        sample.h = std::sqrt(static_cast<double>(*middle));
    }
    sample.nearest.resize(squared.size());
    std::transform(squared.begin(), squared.end(), sample.nearest.begin(),
                   [](float distance) { return std::sqrt(distance); });
    return sample;
}

std::vector<float> sampledNearestDistances(const PointCloud& cloud, std::size_t maxSamples) {
    return sampleSpacing(cloud, maxSamples).nearest;
}

double estimateSpacing(const PointCloud& cloud, std::size_t maxSamples) {
    return sampleSpacing(cloud, maxSamples).h;
}

}  // namespace subscan
