#include "lod/OctreeIndexer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <thread>
#include <tuple>
#include <utility>

#include <fmt/format.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "core/Error.h"
#include "io/TemporaryFolder.h"

namespace subscan::lod {

namespace {

using laz::VoxelKey;

/// Levels deeper than this are not made: a node there is about 1e-9 of the cube, below any
/// scanner's precision, so what still shares it shares one position.
constexpr int kDeepestLevel = 30;
/// Records read from the source at a time.
constexpr std::size_t kPiecePoints = std::size_t{1} << 20;
/// Working bytes a chunk's point needs beside its record: its position (24), its place in the
/// node lists (8) and in the sampling grid (8), with room for the vectors' growth.
constexpr std::size_t kChunkBytesPerPoint = 56;

struct KeyOrder {
    bool operator()(const VoxelKey& a, const VoxelKey& b) const {
        return std::tie(a.level, a.x, a.y, a.z) < std::tie(b.level, b.x, b.y, b.z);
    }
};
template <class Value>
using KeyMap = std::map<VoxelKey, Value, KeyOrder>;

VoxelKey childKey(const VoxelKey& key, int octant) {
    return {key.level + 1, 2 * key.x + (octant & 1), 2 * key.y + ((octant >> 1) & 1),
            2 * key.z + ((octant >> 2) & 1)};
}

VoxelKey parentKey(const VoxelKey& key) {
    return {key.level - 1, key.x >> 1, key.y >> 1, key.z >> 1};
}

/// Positions of records: file coordinate = stored int32 * scale + offset.
glm::dvec3 recordPosition(const std::byte* record, const Quantization& quantization) {
    std::int32_t stored[3];
    std::memcpy(stored, record, sizeof stored);
    return glm::dvec3(stored[0], stored[1], stored[2]) * quantization.scale + quantization.offset;
}

double nodeSide(const OctreeCube& cube, int level) {
    return 2.0 * cube.halfSize / static_cast<double>(std::int64_t{1} << level);
}

glm::dvec3 nodeMin(const OctreeCube& cube, const VoxelKey& key) {
    const double side = nodeSide(cube, key.level);
    return cube.center - cube.halfSize + glm::dvec3(key.x, key.y, key.z) * side;
}

void checkCancelled(const IndexSettings& settings) {
    if (settings.cancelled != nullptr && settings.cancelled->load()) {
        throw Error("interrupted; no output was written");
    }
}

void report(const IndexSettings& settings, double fraction, std::string_view phase) {
    if (settings.progress) {
        settings.progress(std::clamp(fraction, 0.0, 1.0), phase);
    }
}

void writeBytes(const std::filesystem::path& path, std::span<const std::byte> bytes, bool append) {
    std::FILE* file = std::fopen(path.c_str(), append ? "ab" : "wb");
    const bool written =
        file != nullptr && std::fwrite(bytes.data(), 1, bytes.size(), file) == bytes.size();
    const bool closed = file != nullptr && std::fclose(file) == 0;
    if (!written || !closed) {
        throw Error(fmt::format("{}: cannot write temporary data (is the disk full?)",
                                path.parent_path().string()));
    }
}

/// Reads `size` bytes at `offset` into `bytes` (whose memory is reused where it suffices).
void readBytes(const std::filesystem::path& path, std::uint64_t offset, std::size_t size,
               std::vector<std::byte>& bytes) {
    bytes.resize(size);
    std::ifstream file(path, std::ios::binary);
    file.seekg(static_cast<std::streamoff>(offset));
    file.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size));
    if (!file) {
        throw Error(fmt::format("{}: cannot read back temporary data", path.string()));
    }
}

/// The points a node holds: indices into its chunk's records.
using PointList = std::vector<std::uint32_t>;

/// Greedy Poisson-disk acceptance, with its working arrays kept from node to node: a point is
/// accepted when no point accepted before lies closer than the node's spacing. A node's cube is
/// 128 spacings wide (kRootGridCells), so accepted points are listed per cell of the spacing's
/// size in a dense 128^3 grid indexed in Morton order (a point closer than the spacing lies in
/// one of the 27 cells around a candidate's). Candidates are visited block by block (16^3
/// cells, in Morton order) and in a pseudo-random order fixed by the node's key within a block:
/// the grid and the candidates' positions are then read from cache, where a random order over
/// the whole node missed it at every step.
class EvenSampler {
  public:
    EvenSampler() : heads_(std::size_t{1} << (3 * kAxisBits), kNone) {
        for (std::uint32_t v = 0; v < kCells; ++v) {
            std::uint32_t spread = 0;
            for (int bit = 0; bit < kAxisBits; ++bit) {
                spread |= ((v >> bit) & 1u) << (3 * bit);
            }
            spread_[v] = spread;
        }
    }

    /// Moves the points of `children` that the node at `key` accepts into `parent`; the rest
    /// stay.
    void sample(std::span<const glm::dvec3> positions, const OctreeCube& cube, const VoxelKey& key,
                std::span<PointList*> children, PointList& parent) {
        candidates_.clear();
        for (const PointList* child : children) {
            candidates_.insert(candidates_.end(), child->begin(), child->end());
        }
        const double spacing = cube.rootSpacing / static_cast<double>(std::int64_t{1} << key.level);
        accept(positions, spacing, nodeMin(cube, key), key);
        std::size_t at = 0;
        for (PointList* child : children) {
            std::size_t kept = 0;
            for (const std::uint32_t point : *child) {
                if (accepted_[at++] != 0) {
                    parent.push_back(point);
                } else {
                    (*child)[kept++] = point;
                }
            }
            child->resize(kept);
        }
    }

  private:
    static constexpr int kAxisBits = 7;  // 128 cells per axis
    static constexpr std::uint32_t kCells = 1u << kAxisBits;
    static_assert(kCells == kRootGridCells);
    static constexpr int kBlockShift = 3 * 4;  // blocks of 16^3 cells
    static constexpr std::uint32_t kNone = 0xFFFFFFFFu;

    std::uint32_t cellIndex(const glm::ivec3& cell) const {
        return spread_[cell.x] | (spread_[cell.y] << 1) | (spread_[cell.z] << 2);
    }

    void accept(std::span<const glm::dvec3> positions, double spacing, const glm::dvec3& origin,
                const VoxelKey& key) {
        const std::size_t count = candidates_.size();
        // Each candidate's position in cell units and its cell (points on the cube's far faces
        // belong to its last cells, as node membership has it).
        local_.resize(count);
        cellOf_.resize(count);
        constexpr std::size_t kBlocks = std::size_t{1} << (3 * kAxisBits - kBlockShift);
        std::array<std::uint32_t, kBlocks + 1> blockStart{};
        for (std::size_t i = 0; i < count; ++i) {
            const glm::dvec3 scaled = (positions[candidates_[i]] - origin) / spacing;
            local_[i] = glm::vec3(scaled);
            const glm::ivec3 cell =
                glm::clamp(glm::ivec3(glm::floor(scaled)), glm::ivec3(0), glm::ivec3(kCells - 1));
            cellOf_[i] = cellIndex(cell);
            ++blockStart[(cellOf_[i] >> kBlockShift) + 1];
        }
        for (std::size_t b = 0; b < kBlocks; ++b) {
            blockStart[b + 1] += blockStart[b];
        }
        order_.resize(count);
        std::array<std::uint32_t, kBlocks> fill{};
        for (std::uint32_t i = 0; i < count; ++i) {
            const std::uint32_t block = cellOf_[i] >> kBlockShift;
            order_[blockStart[block] + fill[block]++] = i;
        }
        // Fisher-Yates within each block with a splitmix64 stream seeded by the key: the same
        // input gives the same file.
        std::uint64_t state = (static_cast<std::uint64_t>(key.level) << 60) ^
                              (static_cast<std::uint64_t>(key.x) << 40) ^
                              (static_cast<std::uint64_t>(key.y) << 20) ^
                              static_cast<std::uint64_t>(key.z);
        for (std::size_t b = 0; b < kBlocks; ++b) {
            for (std::uint32_t i = blockStart[b + 1]; i > blockStart[b] + 1; --i) {
                state += 0x9E3779B97F4A7C15ull;
                std::uint64_t z = state;
                z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
                z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
                z ^= z >> 31;
                const std::uint32_t span = i - blockStart[b];
                std::swap(order_[i - 1], order_[blockStart[b] + z % span]);
            }
        }

        next_.resize(count);
        accepted_.assign(count, 0);
        touched_.clear();
        for (const std::uint32_t i : order_) {
            const glm::vec3 p = local_[i];
            const glm::ivec3 cell =
                glm::clamp(glm::ivec3(glm::floor(p)), glm::ivec3(0), glm::ivec3(kCells - 1));
            // The candidate's own cell first: at the deep levels most candidates are turned
            // away by a point there.
            bool free = isFarFromCell(p, cellOf_[i]);
            const glm::ivec3 low = glm::max(cell - 1, glm::ivec3(0));
            const glm::ivec3 high = glm::min(cell + 1, glm::ivec3(kCells - 1));
            for (int z = low.z; z <= high.z && free; ++z) {
                const std::uint32_t zBits = spread_[z] << 2;
                for (int y = low.y; y <= high.y && free; ++y) {
                    const std::uint32_t yzBits = zBits | (spread_[y] << 1);
                    for (int x = low.x; x <= high.x && free; ++x) {
                        const std::uint32_t near = yzBits | spread_[x];
                        free = near == cellOf_[i] || isFarFromCell(p, near);
                    }
                }
            }
            if (free) {
                accepted_[i] = 1;
                std::uint32_t& head = heads_[cellOf_[i]];
                if (head == kNone) {
                    touched_.push_back(cellOf_[i]);
                }
                next_[i] = head;
                head = i;
            }
        }
        for (const std::uint32_t cell : touched_) {
            heads_[cell] = kNone;  // the grid is clean for the next node
        }
    }

    /// Whether every point accepted in `cell` lies at least one spacing (one cell) from `p`.
    bool isFarFromCell(const glm::vec3& p, std::uint32_t cell) const {
        for (std::uint32_t j = heads_[cell]; j != kNone; j = next_[j]) {
            const glm::vec3 d = local_[j] - p;
            if (glm::dot(d, d) < 1.0f) {
                return false;
            }
        }
        return true;
    }

    std::array<std::uint32_t, kCells> spread_{};
    std::vector<std::uint32_t> heads_;  // per cell, the last accepted point's candidate index
    PointList candidates_;
    std::vector<glm::vec3> local_;
    std::vector<std::uint32_t> cellOf_;
    std::vector<std::uint32_t> order_;
    std::vector<std::uint32_t> next_;
    std::vector<std::uint8_t> accepted_;
    std::vector<std::uint32_t> touched_;
};

/// Gathers the records of `points` into one contiguous block, `gathered` (whose memory is
/// reused where it suffices).
void gatherRecords(std::span<const std::byte> records, std::size_t length, const PointList& points,
                   std::vector<std::byte>& gathered) {
    gathered.resize(points.size() * length);
    for (std::size_t i = 0; i < points.size(); ++i) {
        std::memcpy(gathered.data() + i * length, records.data() + points[i] * length, length);
    }
}

std::vector<std::byte> gatherRecords(std::span<const std::byte> records, std::size_t length,
                                     const PointList& points) {
    std::vector<std::byte> gathered;
    gatherRecords(records, length, points, gathered);
    return gathered;
}

/// One chunk's points indexed in memory: the subtree below `root`. Every node but the root is
/// finished and written to the sink; the root's accepted points are returned (the levels above
/// draw from them). One per thread, reused from chunk to chunk: its working arrays, the
/// sampler's 8 MB grid among them, are taken once (fresh pages cost a fault each, and freed
/// arrays the size of a chunk go back to the system).
class ChunkIndexer {
  public:
    ChunkIndexer(const OctreeCube& cube, const Quantization& quantization, std::size_t length,
                 std::size_t maxNodePoints, NodeSink& sink)
        : cube_(cube),
          quantization_(quantization),
          length_(length),
          maxNodePoints_(maxNodePoints),
          sink_(sink) {}

    struct Result {
        std::vector<std::byte> rootRecords;
        std::size_t rootPoints = 0;
        std::vector<std::pair<VoxelKey, std::size_t>> written;  // every node written, by key
    };

    /// The chunk's records, to be filled before index().
    std::vector<std::byte>& records() { return records_; }

    Result index(const VoxelKey& root) {
        const std::size_t count = records_.size() / length_;
        positions_.resize(count);
        for (std::size_t i = 0; i < count; ++i) {
            positions_[i] = recordPosition(records_.data() + i * length_, quantization_);
        }
        PointList all(count);
        std::iota(all.begin(), all.end(), 0u);
        Result result;
        PointList rootPoints = build(root, std::move(all), result);
        result.rootPoints = rootPoints.size();
        result.rootRecords = gatherRecords(records_, length_, rootPoints);
        return result;
    }

  private:
    /// Builds the subtree of `key` over `points`, writes every finished node below it and
    /// returns the points `key` holds (a leaf: all of them; the caller's sampling then decides
    /// which stay).
    PointList build(const VoxelKey& key, PointList points, Result& result) {
        const double side = nodeSide(cube_, key.level + 1);
        if (points.size() <= maxNodePoints_ || key.level >= kDeepestLevel ||
            side <
                std::min({quantization_.scale.x, quantization_.scale.y, quantization_.scale.z})) {
            return points;
        }
        // Counted first, so that each part is taken once at its size.
        const glm::dvec3 middle = nodeMin(cube_, key) + side;
        octants_.resize(points.size());
        std::array<std::size_t, 8> sizes{};
        for (std::size_t i = 0; i < points.size(); ++i) {
            const glm::dvec3& p = positions_[points[i]];
            octants_[i] = static_cast<std::uint8_t>(
                (p.x >= middle.x ? 1 : 0) | (p.y >= middle.y ? 2 : 0) | (p.z >= middle.z ? 4 : 0));
            ++sizes[octants_[i]];
        }
        std::array<PointList, 8> parts;
        for (int octant = 0; octant < 8; ++octant) {
            parts[octant].reserve(sizes[octant]);
        }
        for (std::size_t i = 0; i < points.size(); ++i) {
            parts[octants_[i]].push_back(points[i]);
        }
        PointList().swap(points);
        std::array<PointList, 8> held;
        std::vector<PointList*> children;
        std::vector<VoxelKey> childKeys;
        for (int octant = 0; octant < 8; ++octant) {
            if (!parts[octant].empty()) {
                const VoxelKey child = childKey(key, octant);
                held[octant] = build(child, std::move(parts[octant]), result);
                children.push_back(&held[octant]);
                childKeys.push_back(child);
            }
        }
        PointList mine;
        sampler_.sample(positions_, cube_, key, children, mine);
        for (std::size_t i = 0; i < children.size(); ++i) {
            write(childKeys[i], *children[i], result);
        }
        return mine;
    }

    void write(const VoxelKey& key, const PointList& points, Result& result) {
        if (points.empty()) {
            return;
        }
        gatherRecords(records_, length_, points, gathered_);
        sink_.writeNode(key, gathered_, points.size());
        result.written.emplace_back(key, points.size());
    }

    OctreeCube cube_;
    Quantization quantization_;
    std::size_t length_;
    std::size_t maxNodePoints_;
    NodeSink& sink_;
    std::vector<std::byte> records_;
    std::vector<glm::dvec3> positions_;
    std::vector<std::uint8_t> octants_;
    std::vector<std::byte> gathered_;
    EvenSampler sampler_;
};

/// Cells of a count grid at `level` (2^level per axis), flattened x fastest.
std::size_t gridIndex(const VoxelKey& key, int level) {
    const std::size_t n = std::size_t{1} << level;
    return (static_cast<std::size_t>(key.z) * n + static_cast<std::size_t>(key.y)) * n +
           static_cast<std::size_t>(key.x);
}

struct Chunking {
    int gridLevel = 0;
    std::vector<VoxelKey> chunks;
    std::vector<std::uint32_t> chunkOfCell;  // per cell of the grid
};

/// Cuts the cloud into chunks of at most `maxPoints` (where the grid allows) from its point
/// counts per cell of a 2^gridLevel grid: top-down, a node with few enough points is a chunk.
Chunking cutIntoChunks(std::vector<std::uint32_t> counts, int gridLevel, std::size_t maxPoints) {
    // Sums per node of every coarser level, finest first.
    std::vector<std::vector<std::uint64_t>> sums(gridLevel + 1);
    sums[gridLevel].assign(counts.begin(), counts.end());
    for (int level = gridLevel - 1; level >= 0; --level) {
        const std::int32_t n = 1 << level;
        sums[level].assign(static_cast<std::size_t>(n) * n * n, 0);
        for (std::int32_t z = 0; z < 2 * n; ++z) {
            for (std::int32_t y = 0; y < 2 * n; ++y) {
                for (std::int32_t x = 0; x < 2 * n; ++x) {
                    sums[level][gridIndex({level, x / 2, y / 2, z / 2}, level)] +=
                        sums[level + 1][gridIndex({level + 1, x, y, z}, level + 1)];
                }
            }
        }
    }
    Chunking chunking;
    chunking.gridLevel = gridLevel;
    chunking.chunkOfCell.assign(counts.size(), 0xFFFFFFFFu);
    std::vector<VoxelKey> pending{{0, 0, 0, 0}};
    while (!pending.empty()) {
        const VoxelKey key = pending.back();
        pending.pop_back();
        const std::uint64_t count = sums[key.level][gridIndex(key, key.level)];
        if (count == 0) {
            continue;
        }
        if (count > maxPoints && key.level < gridLevel) {
            for (int octant = 0; octant < 8; ++octant) {
                pending.push_back(childKey(key, octant));
            }
            continue;
        }
        const auto id = static_cast<std::uint32_t>(chunking.chunks.size());
        chunking.chunks.push_back(key);
        const std::int32_t span = 1 << (gridLevel - key.level);
        for (std::int32_t z = 0; z < span; ++z) {
            for (std::int32_t y = 0; y < span; ++y) {
                for (std::int32_t x = 0; x < span; ++x) {
                    const VoxelKey cell{gridLevel, key.x * span + x, key.y * span + y,
                                        key.z * span + z};
                    chunking.chunkOfCell[gridIndex(cell, gridLevel)] = id;
                }
            }
        }
    }
    return chunking;
}

/// Where the chunks' records wait to be indexed, and the chunks' top nodes wait for the levels
/// above: in memory when the whole cloud fits the budget, else in temporary files.
class ChunkStore {
  public:
    ChunkStore(std::size_t chunks, std::size_t length, const std::filesystem::path* folder)
        : length_(length), memory_(chunks), folder_(folder != nullptr ? *folder : "") {
        if (!folder_.empty()) {
            writeBytes(folder_ / "roots.bin", {}, false);
        }
    }
    bool inMemory() const { return folder_.empty(); }

    /// Room for a chunk's records in memory (a hint; files need none).
    void reserve(std::size_t id, std::size_t bytes) {
        if (inMemory()) {
            memory_[id].reserve(bytes);
        }
    }
    /// Appends records to a chunk (one thread at a time).
    void append(std::size_t id, std::span<const std::byte> records) {
        if (inMemory()) {
            memory_[id].insert(memory_[id].end(), records.begin(), records.end());
        } else {
            writeBytes(chunkFile(id), records, true);
        }
    }
    /// A chunk's records into `records`, once (any thread, each chunk from one).
    void take(std::size_t id, std::vector<std::byte>& records) {
        if (inMemory()) {
            records = std::move(memory_[id]);
            return;
        }
        const std::filesystem::path file = chunkFile(id);
        std::error_code missing;
        const auto size = std::filesystem::file_size(file, missing);
        if (missing) {
            records.clear();
            return;
        }
        readBytes(file, 0, static_cast<std::size_t>(size), records);
        std::filesystem::remove(file);
    }

    /// Keeps a chunk's top node (any thread).
    void putRoot(const VoxelKey& key, std::vector<std::byte> records) {
        std::lock_guard lock(mutex_);
        const std::size_t points = records.size() / length_;
        if (inMemory()) {
            roots_[key] = {0, points};
            rootRecords_[key] = std::move(records);
        } else {
            writeBytes(folder_ / "roots.bin", records, true);
            roots_[key] = {rootsSize_, points};
            rootsSize_ += records.size();
        }
    }
    bool hasRoot(const VoxelKey& key) const { return roots_.contains(key); }
    std::vector<std::byte> takeRoot(const VoxelKey& key) {
        const auto& [offset, points] = roots_.at(key);
        if (inMemory()) {
            return std::move(rootRecords_.at(key));
        }
        std::vector<std::byte> records;
        readBytes(folder_ / "roots.bin", offset, points * length_, records);
        return records;
    }

  private:
    std::filesystem::path chunkFile(std::size_t id) const {
        return folder_ / fmt::format("chunk-{}.bin", id);
    }

    std::size_t length_;
    std::vector<std::vector<std::byte>> memory_;
    std::filesystem::path folder_;
    std::mutex mutex_;
    KeyMap<std::pair<std::uint64_t, std::size_t>> roots_;  // offset in roots.bin, points
    KeyMap<std::vector<std::byte>> rootRecords_;
    std::uint64_t rootsSize_ = 0;
};

/// Buffers the distribution may hold beside one per chunk, in flight to the files.
constexpr std::size_t kSpareBuffers = 2;

/// Appends chunks' full buffers to their files on a thread of its own, so that the kernel's
/// copy into the page cache (a third of the distribution's time on one thread) overlaps the
/// reading and sorting of the records that follow. Hands back an empty buffer of the same
/// capacity for each full one; at most kSpareBuffers wait to be written.
class BackgroundAppender {
  public:
    BackgroundAppender(ChunkStore& store, std::size_t capacity) : store_(store) {
        for (std::size_t i = 0; i < kSpareBuffers; ++i) {
            spares_.emplace_back().reserve(capacity);
        }
        writer_ = std::jthread([this] { write(); });
    }
    ~BackgroundAppender() { stop(); }
    BackgroundAppender(const BackgroundAppender&) = delete;
    BackgroundAppender& operator=(const BackgroundAppender&) = delete;

    /// Queues `full` for chunk `id`'s file; returns an empty buffer to go on with. Throws the
    /// error of an earlier write.
    std::vector<std::byte> exchange(std::size_t id, std::vector<std::byte> full) {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return !spares_.empty() || failure_; });
        if (failure_) {
            std::rethrow_exception(failure_);
        }
        std::vector<std::byte> empty = std::move(spares_.back());
        spares_.pop_back();
        queue_.emplace_back(id, std::move(full));
        changed_.notify_all();
        return empty;
    }

    /// Waits until every queued buffer is written; throws a write's error.
    void finish() {
        stop();
        if (failure_) {
            std::rethrow_exception(failure_);
        }
    }

  private:
    void write() {
        for (;;) {
            std::pair<std::size_t, std::vector<std::byte>> job;
            {
                std::unique_lock lock(mutex_);
                changed_.wait(lock, [&] { return !queue_.empty() || stopping_; });
                if (queue_.empty()) {
                    return;
                }
                job = std::move(queue_.front());
                queue_.pop_front();
            }
            try {
                store_.append(job.first, job.second);
            } catch (...) {
                std::lock_guard lock(mutex_);
                failure_ = std::current_exception();
                queue_.clear();
            }
            job.second.clear();
            std::lock_guard lock(mutex_);
            spares_.push_back(std::move(job.second));
            changed_.notify_all();
        }
    }

    void stop() {
        {
            std::lock_guard lock(mutex_);
            stopping_ = true;
            changed_.notify_all();
        }
        if (writer_.joinable()) {
            writer_.join();
        }
    }

    ChunkStore& store_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::pair<std::size_t, std::vector<std::byte>>> queue_;
    std::vector<std::vector<std::byte>> spares_;
    std::exception_ptr failure_;
    bool stopping_ = false;
    std::jthread writer_;
};

class Indexer {
  public:
    Indexer(PointRecordSource& source, NodeSink& sink, const IndexSettings& settings)
        : source_(source),
          sink_(sink),
          settings_(settings),
          info_(source.info()),
          length_(info_.format.recordLength()),
          threads_(settings.threads != 0 ? settings.threads
                                         : std::max(1u, std::thread::hardware_concurrency())) {
        summary_.cube = octreeCubeFor(info_.min, info_.max);
        // The whole cloud stays in memory when it fits a third of the budget twice over (read,
        // then sorted into chunks). Otherwise each thread indexes one chunk at a time in three
        // quarters of the budget; the rest is for the distribution's buffers and the encoding.
        const std::size_t perPoint = length_ + kChunkBytesPerPoint;
        inMemory_ = info_.pointCount * length_ * 3 <= settings.memoryBytes;
        maxChunkPoints_ = settings.memoryBytes * 3 / 4 / threads_ / perPoint;
        if (inMemory_) {
            // Enough chunks to keep every thread busy, none so small that its top node would
            // hold most of its points.
            maxChunkPoints_ = std::min<std::size_t>(
                maxChunkPoints_, info_.pointCount / (4 * static_cast<std::size_t>(threads_)) + 1);
        }
        maxChunkPoints_ =
            std::clamp<std::size_t>(maxChunkPoints_, settings.maxNodePoints * 8, 0xFFFFFFFFu);
    }

    IndexSummary run() {
        if (info_.pointCount == 0) {
            throw Error(fmt::format("{}: holds no points; there is nothing to index", info_.name));
        }
        // 128 cells per axis hold any cloud up to 2^27 points in chunks of millions; finer
        // grids for more (256^3 counters: 64 MB).
        const int gridLevel = info_.pointCount <= (std::uint64_t{1} << 27) ? 7 : 8;
        if (inMemory_) {
            std::vector<std::byte> records;
            records.reserve(info_.pointCount * length_);
            readAll(0.0, 0.3, "reading", [&](const std::vector<std::byte>& piece, std::size_t) {
                records.insert(records.end(), piece.begin(), piece.end());
            });
            // A cloud of one chunk's size is that chunk: no grid to count and cut.
            const Chunking chunking =
                info_.pointCount <= maxChunkPoints_
                    ? Chunking{0, {VoxelKey{0, 0, 0, 0}}, {}}
                    : cutIntoChunks(countCells(records, gridLevel), gridLevel, maxChunkPoints_);
            ChunkStore store(chunking.chunks.size(), length_, nullptr);
            if (chunking.chunks.size() == 1) {
                store.append(0, records);
            } else {
                distribute(records, chunking, store);
            }
            std::vector<std::byte>().swap(records);
            indexChunks(chunking, store, 0.35);
            buildTop(chunking, store);
        } else {
            TemporaryFolder folder(settings_.temporaryDirectory, "subscan-index");
            std::vector<std::uint32_t> counts(std::size_t{1} << (3 * gridLevel), 0);
            std::vector<std::uint32_t> cells;
            readAll(0.0, 0.15, "counting", [&](const std::vector<std::byte>& piece, std::size_t) {
                cellsOf(piece, gridLevel, cells);
                for (const std::uint32_t cell : cells) {
                    ++counts[cell];
                }
            });
            const Chunking chunking = cutIntoChunks(std::move(counts), gridLevel, maxChunkPoints_);
            ChunkStore store(chunking.chunks.size(), length_, &folder.path());
            distributeFromSource(chunking, store);
            indexChunks(chunking, store, 0.35);
            buildTop(chunking, store);
        }
        report(settings_, 1.0, "done");
        return summary_;
    }

  private:
    void count(const VoxelKey& key, std::size_t points) {
        if (summary_.levels.size() <= static_cast<std::size_t>(key.level)) {
            summary_.levels.resize(key.level + 1);
        }
        summary_.levels[key.level].nodes += 1;
        summary_.levels[key.level].points += points;
        summary_.points += points;
        summary_.largestNode = std::max(summary_.largestNode, points);
    }

    void countWritten(const ChunkIndexer::Result& result) {
        for (const auto& [key, points] : result.written) {
            count(key, points);
        }
    }

    void writeNode(const VoxelKey& key, std::span<const std::byte> records, std::size_t points) {
        sink_.writeNode(key, records, points);
        count(key, points);
    }

    /// Reads the whole source in pieces, calling `each(records, count)`.
    template <class Each>
    void readAll(double from, double to, std::string_view phase, const Each& each) {
        report(settings_, from, phase);  // the phase's name from its start
        source_.rewind();
        std::vector<std::byte> piece;
        std::uint64_t done = 0;
        for (;;) {
            checkCancelled(settings_);
            piece.clear();
            const std::size_t read = source_.read(piece, kPiecePoints);
            if (read == 0) {
                break;
            }
            each(piece, read);
            done += read;
            report(settings_,
                   from + (to - from) * static_cast<double>(done) /
                              static_cast<double>(info_.pointCount),
                   phase);
        }
        if (done != info_.pointCount) {
            throw Error(fmt::format("{}: gave {} points where its header promised {}", info_.name,
                                    done, info_.pointCount));
        }
    }

    /// Each record's cell of the 2^gridLevel grid.
    void cellsOf(std::span<const std::byte> records, int gridLevel,
                 std::vector<std::uint32_t>& cells) const {
        const std::size_t n = records.size() / length_;
        cells.resize(n);
        inParallelOn(n, [&](std::size_t i) {
            const glm::dvec3 p = recordPosition(records.data() + i * length_, info_.quantization);
            cells[i] = static_cast<std::uint32_t>(
                gridIndex(nodeKeyAt(summary_.cube, p, gridLevel), gridLevel));
        });
    }

    std::vector<std::uint32_t> countCells(std::span<const std::byte> records, int gridLevel) const {
        std::vector<std::uint32_t> cells;
        cellsOf(records, gridLevel, cells);
        std::vector<std::uint32_t> counts(std::size_t{1} << (3 * gridLevel), 0);
        for (const std::uint32_t cell : cells) {
            ++counts[cell];
        }
        return counts;
    }

    /// Runs work(i) for i < count on the indexer's threads, in contiguous ranges.
    template <class Work>
    void inParallelOn(std::size_t count, const Work& work) const {
        const auto range = [&](std::size_t thread) {
            const std::size_t last = (thread + 1) * count / threads_;
            for (std::size_t i = thread * count / threads_; i < last; ++i) {
                work(i);
            }
        };
        std::vector<std::jthread> workers;
        for (std::size_t thread = 1; thread < threads_; ++thread) {
            workers.emplace_back(range, thread);
        }
        range(0);
    }

    /// Sorts `records` into their chunks, each chunk's memory taken once at its final size.
    void distribute(std::span<const std::byte> records, const Chunking& chunking,
                    ChunkStore& store) {
        std::vector<std::uint32_t> cells;
        cellsOf(records, chunking.gridLevel, cells);
        std::vector<std::size_t> sizes(chunking.chunks.size(), 0);
        for (std::uint32_t& cell : cells) {
            cell = chunking.chunkOfCell[cell];
            sizes[cell] += length_;
        }
        for (std::size_t id = 0; id < sizes.size(); ++id) {
            store.reserve(id, sizes[id]);
        }
        for (std::size_t i = 0; i < cells.size(); ++i) {
            store.append(cells[i], records.subspan(i * length_, length_));
        }
    }

    /// Reads the source again and appends every record to its chunk's file. Each chunk has a
    /// buffer of an equal share of a quarter of the budget (at least 1,024 records, which
    /// thousands of chunks under a small --memory would exceed it by), taken once and written
    /// out whenever it fills: memory does not grow with the order the pieces come in (a
    /// survey's come region by region), and each page is touched once. Buffers that grew by
    /// appending and were freed after every write-out spent 16.6 of 30.5 s indexing 44 M points
    /// here, copying as they grew and faulting in fresh pages each round.
    void distributeFromSource(const Chunking& chunking, ChunkStore& store) {
        const std::size_t chunks = chunking.chunks.size();
        const std::size_t share =
            std::max<std::size_t>(settings_.memoryBytes / 4 / (chunks + kSpareBuffers) / length_,
                                  1024) *
            length_;
        std::vector<std::vector<std::byte>> buffers(chunks);
        for (std::vector<std::byte>& buffer : buffers) {
            buffer.reserve(share);
        }
        BackgroundAppender appender(store, share);
        std::vector<std::uint32_t> cells;
        readAll(0.15, 0.35, "distributing",
                [&](const std::vector<std::byte>& piece, std::size_t n) {
                    cellsOf(piece, chunking.gridLevel, cells);
                    for (std::size_t i = 0; i < n; ++i) {
                        const std::size_t id = chunking.chunkOfCell[cells[i]];
                        if (buffers[id].size() == share) {
                            buffers[id] = appender.exchange(id, std::move(buffers[id]));
                        }
                        const std::byte* record = piece.data() + i * length_;
                        buffers[id].insert(buffers[id].end(), record, record + length_);
                    }
                });
        for (std::size_t id = 0; id < chunks; ++id) {
            if (!buffers[id].empty()) {
                appender.exchange(id, std::move(buffers[id]));
            }
        }
        appender.finish();
    }

    /// Indexes the chunks on `threads_` threads; each chunk's top node goes to the store.
    void indexChunks(const Chunking& chunking, ChunkStore& store, double from) {
        std::mutex mutex;
        std::size_t nextChunk = 0;
        std::uint64_t pointsDone = 0;
        std::exception_ptr failure;
        summary_.chunks = chunking.chunks.size();

        const auto work = [&] {
            ChunkIndexer indexer(summary_.cube, info_.quantization, length_,
                                 settings_.maxNodePoints, sink_);
            for (;;) {
                std::size_t id = 0;
                {
                    std::lock_guard lock(mutex);
                    if (failure || nextChunk == chunking.chunks.size()) {
                        return;
                    }
                    id = nextChunk++;
                }
                try {
                    checkCancelled(settings_);
                    store.take(id, indexer.records());
                    const std::size_t points = indexer.records().size() / length_;
                    ChunkIndexer::Result result = indexer.index(chunking.chunks[id]);
                    store.putRoot(chunking.chunks[id], std::move(result.rootRecords));
                    std::lock_guard lock(mutex);
                    countWritten(result);
                    pointsDone += points;
                    report(settings_,
                           from + (0.95 - from) * static_cast<double>(pointsDone) /
                                      static_cast<double>(info_.pointCount),
                           "indexing");
                } catch (...) {
                    std::lock_guard lock(mutex);
                    if (!failure) {
                        failure = std::current_exception();
                    }
                }
            }
        };
        {
            std::vector<std::jthread> workers;
            for (unsigned thread = 1; thread < threads_; ++thread) {
                workers.emplace_back(work);
            }
            work();
        }
        if (failure) {
            std::rethrow_exception(failure);
        }
    }

    /// The levels above the chunks: each node samples its children's points, depth first, so
    /// only the nodes along one path and their children are in memory at once.
    void buildTop(const Chunking& chunking, ChunkStore& store) {
        KeyMap<bool> above;  // every strict ancestor of a chunk
        for (const VoxelKey& chunk : chunking.chunks) {
            for (VoxelKey key = chunk; key.level > 0;) {
                key = parentKey(key);
                above[key] = true;
            }
        }
        const VoxelKey root{0, 0, 0, 0};
        const std::vector<std::byte> rootRecords =
            above.empty() ? store.takeRoot(root) : buildAbove(root, above, store);
        writeNode(root, rootRecords, rootRecords.size() / length_);
    }

    /// Returns the records `key` holds after sampling its children, whose rest it writes.
    std::vector<std::byte> buildAbove(const VoxelKey& key, const KeyMap<bool>& above,
                                      ChunkStore& store) {
        checkCancelled(settings_);
        std::vector<VoxelKey> childKeys;
        std::vector<std::byte> records;  // the children's points, child after child
        std::vector<std::size_t> childStart;
        for (int octant = 0; octant < 8; ++octant) {
            const VoxelKey child = childKey(key, octant);
            std::vector<std::byte> held;
            if (store.hasRoot(child)) {
                held = store.takeRoot(child);
            } else if (above.contains(child)) {
                held = buildAbove(child, above, store);
            } else {
                continue;
            }
            childKeys.push_back(child);
            childStart.push_back(records.size() / length_);
            records.insert(records.end(), held.begin(), held.end());
        }
        childStart.push_back(records.size() / length_);

        const std::size_t count = records.size() / length_;
        std::vector<glm::dvec3> positions(count);
        for (std::size_t i = 0; i < count; ++i) {
            positions[i] = recordPosition(records.data() + i * length_, info_.quantization);
        }
        std::vector<PointList> lists(childKeys.size());
        std::vector<PointList*> children;
        for (std::size_t c = 0; c < childKeys.size(); ++c) {
            for (std::size_t i = childStart[c]; i < childStart[c + 1]; ++i) {
                lists[c].push_back(static_cast<std::uint32_t>(i));
            }
            children.push_back(&lists[c]);
        }
        PointList mine;
        sampler_.sample(positions, summary_.cube, key, children, mine);
        for (std::size_t c = 0; c < childKeys.size(); ++c) {
            if (!lists[c].empty()) {
                writeNode(childKeys[c], gatherRecords(records, length_, lists[c]), lists[c].size());
            }
        }
        return gatherRecords(records, length_, mine);
    }

    PointRecordSource& source_;
    NodeSink& sink_;
    const IndexSettings& settings_;
    PointRecordSourceInfo info_;
    std::size_t length_;
    unsigned threads_;
    bool inMemory_ = false;
    std::size_t maxChunkPoints_ = 0;
    IndexSummary summary_;
    EvenSampler sampler_;
};

}  // namespace

OctreeCube octreeCubeFor(const glm::dvec3& min, const glm::dvec3& max) {
    OctreeCube cube;
    cube.center = (min + max) * 0.5;
    const glm::dvec3 size = max - min;
    const double extent = std::max({size.x, size.y, size.z});
    // A hair larger than the bounds, so that the largest coordinates fall inside; at least a
    // millimetre-sized cube around a single point.
    cube.halfSize = std::max(extent * 0.5 * (1.0 + 1e-9), 1e-3);
    cube.rootSpacing = 2.0 * cube.halfSize / kRootGridCells;
    return cube;
}

laz::VoxelKey nodeKeyAt(const OctreeCube& cube, const glm::dvec3& position, int level) {
    const double cells = static_cast<double>(std::int64_t{1} << level);
    const glm::dvec3 relative = (position - (cube.center - cube.halfSize)) / (2.0 * cube.halfSize);
    const glm::dvec3 cell = glm::clamp(glm::floor(relative * cells), 0.0, cells - 1.0);
    return {level, static_cast<std::int32_t>(cell.x), static_cast<std::int32_t>(cell.y),
            static_cast<std::int32_t>(cell.z)};
}

IndexSummary buildOctree(PointRecordSource& source, NodeSink& sink, const IndexSettings& settings) {
    return Indexer(source, sink, settings).run();
}

}  // namespace subscan::lod
