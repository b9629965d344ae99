#include "lod/NodeSource.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>
#include <glm/vector_relational.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "io/LasHeader.h"
#include "io/LasReader.h"
#include "io/MappedFile.h"
#include "io/laz/LazDecoder.h"

namespace subscan::lod {

namespace {

/// 2^15 nodes a side, about 3e-5 of the cube: deeper than any indexer goes for real surveys
/// (PDAL's lone star scan: 4 levels; Autzen tiled 60 x 60: 8).
constexpr int kDeepestStreamedLevel = 15;

/// A key packed into one word, ordered as nodes() is: by level, then x, y, z (20 bits each;
/// setNodes refuses keys deeper than kDeepestStreamedLevel, whose coordinates would not fit).
std::uint64_t packedKey(const laz::VoxelKey& key) {
    return (static_cast<std::uint64_t>(key.level) << 60) |
           (static_cast<std::uint64_t>(key.x) << 40) | (static_cast<std::uint64_t>(key.y) << 20) |
           static_cast<std::uint64_t>(key.z);
}

/// A mapped file's bytes as text (the JSON of ept.json and its hierarchy).
std::string_view textOf(const MappedFile& file) {
    return {reinterpret_cast<const char*>(file.bytes().data()), file.bytes().size()};
}

nlohmann::json parseJson(std::string_view text) {
    nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
    if (json.is_discarded()) {
        throw Error("is not valid JSON");
    }
    return json;
}

/// "D-X-Y-Z" as EPT names nodes.
std::optional<laz::VoxelKey> parseEptKey(std::string_view name) {
    std::array<std::int32_t, 4> parts{};
    const char* at = name.data();
    const char* const end = name.data() + name.size();
    for (std::size_t i = 0; i < parts.size(); ++i) {
        if (i > 0) {
            if (at == end || *at != '-') {
                return std::nullopt;
            }
            ++at;
        }
        const auto [next, error] = std::from_chars(at, end, parts[i]);
        if (error != std::errc{}) {
            return std::nullopt;  // not a number, or beyond 32 bits
        }
        at = next;
    }
    if (at != end) {
        return std::nullopt;
    }
    return laz::VoxelKey{parts[0], parts[1], parts[2], parts[3]};
}

class CopcSource final : public NodeSource {
  public:
    explicit CopcSource(const std::filesystem::path& path) : file_(path) {
        const std::span<const std::byte> bytes = file_.bytes();
        ReadContext context;
        header_ = parseLasHeader(bytes, bytes.size(), context);
        const std::optional<std::span<const std::byte>> record =
            findLasVlr(bytes, header_, "copc", 1);
        if (!record || !header_.laszipRecord) {
            throw Error("is not a COPC file (no COPC info record)");
        }
        const laz::CopcInfo copc = laz::parseCopcInfo(*record);
        layout_ = laz::parseLaszipRecord(*header_.laszipRecord, header_.pointFormat,
                                         header_.recordLength);
        std::vector<StreamedNode> nodes;
        for (const laz::CopcNode& node : laz::readCopcHierarchy(bytes, copc)) {
            nodes.push_back({node.key, node.chunk.pointCount});
            chunks_[packedKey(node.key)] = node.chunk;
        }
        info_.name = path.string();
        info_.format = "las";
        info_.cube = {copc.center, copc.halfSize, copc.rootSpacing};
        if (!(info_.cube.halfSize > 0.0 && info_.cube.halfSize <= kMaxCoordinate &&
              info_.cube.rootSpacing > 0.0 && std::isfinite(info_.cube.rootSpacing) &&
              std::abs(info_.cube.center.x) <= kMaxCoordinate &&
              std::abs(info_.cube.center.y) <= kMaxCoordinate &&
              std::abs(info_.cube.center.z) <= kMaxCoordinate)) {
            throw Error(
                "the COPC info's cube (centre, half size, spacing) is not finite and "
                "positive");
        }
        info_.bounds = boundsWithinCube(header_.declaredBounds);
        setNodes(std::move(nodes));
        if (info_.points != header_.pointCount) {
            info_.warnings.push_back(fmt::format(
                "the COPC hierarchy's nodes hold {} points, but the LAS header declares {}; the "
                "hierarchy's are read",
                info_.points, header_.pointCount));
        }
        info_.formatDetail = fmt::format(
            "COPC 1.0 (LAZ, LAS 1.{}, point format {}): octree of {} levels, {} nodes, root "
            "spacing {:.6g}",
            header_.versionMinor, header_.pointFormat, this->nodes().back().key.level + 1,
            this->nodes().size(), copc.rootSpacing);
        // Colour depth is decided on the root's records for every node alike (a damaged root
        // is left out when loaded; the others then decide each on their own).
        try {
            rootRecords_ = records(0);
        } catch (const Error&) {
            rootRecords_.clear();
        }
    }

    PointCloud load(std::size_t index) const override {
        const std::vector<std::byte> decoded =
            index == 0 && !rootRecords_.empty() ? rootRecords_ : records(index);
        std::vector<std::string> warnings;
        return lasRecordsToCloud(file_.bytes(), header_, decoded,
                                 rootRecords_.empty() ? decoded : rootRecords_, ReadContext{},
                                 warnings);
    }

  private:
    /// The header's bounds where they are finite and lie in the octree's cube (a writer's
    /// rounding aside); else the cube's, with a warning: they frame the view and are the
    /// merged clouds' origin.
    Bounds boundsWithinCube(const Bounds& declared) {
        Bounds cube;
        cube.add(info_.cube.center - info_.cube.halfSize);
        cube.add(info_.cube.center + info_.cube.halfSize);
        const glm::dvec3 slack(1e-6 * info_.cube.halfSize);
        const bool inside = !declared.empty() &&
                            glm::all(glm::greaterThanEqual(declared.min, cube.min - slack)) &&
                            glm::all(glm::lessThanEqual(declared.max, cube.max + slack));
        if (inside) {
            return declared;
        }
        info_.warnings.push_back(fmt::format(
            "the LAS header bounds ({} {} {} to {} {} {}) do not lie in the COPC octree's cube; "
            "the cube's are used",
            declared.min.x, declared.min.y, declared.min.z, declared.max.x, declared.max.y,
            declared.max.z));
        return cube;
    }

    std::vector<std::byte> records(std::size_t index) const {
        const StreamedNode& node = nodes()[index];
        const laz::Chunk& chunk = chunks_.at(packedKey(node.key));
        // A count LAZ cannot fit in the chunk's bytes is damage, not points to allocate for.
        if (chunk.pointCount >
            laz::kMostLazPointsPerByte * std::max<std::uint64_t>(chunk.byteSize, 1)) {
            throw Error(fmt::format("{}: the hierarchy gives {} points for a chunk of {} bytes",
                                    nodeName(node.key), chunk.pointCount, chunk.byteSize));
        }
        std::vector<std::byte> decoded(chunk.pointCount * header_.recordLength);
        try {
            laz::decodeChunk(file_.bytes().subspan(chunk.offset, chunk.byteSize), chunk.pointCount,
                             layout_, decoded.data());
        } catch (const Error& error) {
            throw Error(fmt::format("{}: {}", nodeName(node.key), error.what()));
        }
        if (file_.shrank()) {
            throw Error(
                fmt::format("{}: the file was truncated while it was read", nodeName(node.key)));
        }
        return decoded;
    }

    MappedFile file_;
    LasHeader header_;
    laz::LazLayout layout_;
    std::map<std::uint64_t, laz::Chunk> chunks_;
    std::vector<std::byte> rootRecords_;
};

class EptSource final : public NodeSource {
  public:
    explicit EptSource(const std::filesystem::path& json) : folder_(json.parent_path()) {
        EptDescription ept;
        try {
            ept = parseEptDescription(textOf(MappedFile(json)));
        } catch (const Error& error) {
            throw Error(fmt::format("{}: {}", json.string(), error.what()));
        }
        info_.name = folder_.string();
        info_.format = "las";  // LAZ tiles: LAS-family data (Z up)
        info_.cube = ept.cube;
        info_.wkt = ept.wkt;
        info_.bounds = sourcesBounds(folder_).value_or(ept.bounds);
        std::vector<StreamedNode> nodes;
        readHierarchy("0-0-0-0", nodes);
        std::uint64_t listed = 0;
        for (const StreamedNode& node : nodes) {
            listed += node.pointCount;
        }
        if (listed != ept.points) {
            info_.warnings.push_back(
                fmt::format("ept.json declares {} points, but its hierarchy lists {}; the "
                            "hierarchy's are read",
                            ept.points, listed));
        }
        setNodes(std::move(nodes));
        try {
            rootRecords_ = readTile(folder_ / "ept-data" / "0-0-0-0.laz").records.bytes;
        } catch (const Error&) {
            rootRecords_.clear();  // left out with a warning when loaded
        }
        info_.formatDetail = fmt::format(
            "EPT {} (LAZ tiles): octree of {} levels, {} nodes, root spacing {:.6g}", ept.version,
            this->nodes().back().key.level + 1, this->nodes().size(), info_.cube.rootSpacing);
    }

    PointCloud load(std::size_t index) const override {
        const StreamedNode& node = nodes()[index];
        const std::filesystem::path tile = eptTilePath(folder_, node.key);
        const auto fail = [&](const std::string& what) {
            return Error(fmt::format("{}: {}", nodeName(node.key), what));
        };
        std::error_code missing;
        if (!std::filesystem::is_regular_file(tile, missing)) {
            throw fail(fmt::format("its tile {} is missing", tile.string()));
        }
        PointCloud cloud;
        try {
            const TileRecords records = readTile(tile);
            std::vector<std::string> warnings;
            // Colour depth decided on the root tile's records for every tile alike (a dark
            // tile of 16-bit colours would otherwise pass for 8-bit and show 257 times too
            // bright); a tile decides on its own where the root could not be read.
            cloud = lasRecordsToCloud(records.file.bytes(), records.header, records.records.bytes,
                                      rootRecords_.empty() ? records.records.bytes : rootRecords_,
                                      ReadContext{}, warnings);
        } catch (const Error& error) {
            throw fail(fmt::format("{}: {}", tile.string(), error.what()));
        }
        if (cloud.size() != node.pointCount) {
            throw fail(fmt::format("its tile holds {} points, but the hierarchy says {}",
                                   cloud.size(), node.pointCount));
        }
        return cloud;
    }

  private:
    struct TileRecords {
        MappedFile file;
        LasHeader header;
        LasRecords records;
    };
    static TileRecords readTile(const std::filesystem::path& tile) {
        MappedFile file(tile);
        ReadContext context;
        context.decodeThreads = 1;  // nodes load on threads of their own
        LasHeader header = parseLasHeader(file.bytes(), file.bytes().size(), context);
        LasRecords records = readLasRecords(file.bytes(), context);
        return {std::move(file), header, std::move(records)};
    }

    static std::string eptName(const laz::VoxelKey& key) {
        return fmt::format("{}-{}-{}-{}", key.level, key.x, key.y, key.z);
    }

    /// The union of ept-sources/list.json's "bounds", where it gives them for every source:
    /// the points' exact bounds (ept.json's "boundsConforming" are rounded outwards to whole
    /// units, up to a metre off on PDAL's lone star scan).
    static std::optional<Bounds> sourcesBounds(const std::filesystem::path& folder) {
        try {
            const nlohmann::json list =
                parseJson(textOf(MappedFile(folder / "ept-sources" / "list.json")));
            Bounds bounds;
            for (const nlohmann::json& source : list) {
                const std::vector<double> b = source.at("bounds").get<std::vector<double>>();
                if (b.size() != 6) {
                    return std::nullopt;
                }
                bounds.add({b[0], b[1], b[2]});
                bounds.add({b[3], b[4], b[5]});
            }
            return bounds.empty() ? std::nullopt : std::optional<Bounds>(bounds);
        } catch (const std::exception&) {
            return std::nullopt;  // optional: the conforming bounds serve
        }
    }

    /// Reads ept-hierarchy/NAME.json and every page it points to.
    void readHierarchy(const std::string& name, std::vector<StreamedNode>& nodes) {
        const std::filesystem::path path = folder_ / "ept-hierarchy" / (name + ".json");
        if (!visited_.insert(name).second) {
            return;
        }
        EptHierarchyPage page;
        try {
            page = parseEptHierarchyPage(textOf(MappedFile(path)));
        } catch (const Error& error) {
            const Error named(fmt::format("{}: {}", path.string(), error.what()));
            if (name == "0-0-0-0") {
                throw named;
            }
            // A page below the root: its subtree is left out, the rest still shows.
            info_.warnings.push_back(
                fmt::format("{}; the nodes it lists are left out", named.what()));
            return;
        }
        nodes.insert(nodes.end(), page.nodes.begin(), page.nodes.end());
        for (const laz::VoxelKey& key : page.pages) {
            const std::string next = eptName(key);
            if (next != name) {
                readHierarchy(next, nodes);
            }
        }
    }

    std::filesystem::path folder_;
    std::set<std::string> visited_;
    std::vector<std::byte> rootRecords_;
};

}  // namespace

EptDescription parseEptDescription(std::string_view text) {
    const nlohmann::json ept = parseJson(text);
    EptDescription description;
    try {
        const std::string dataType = ept.at("dataType").get<std::string>();
        if (dataType != "laszip") {
            throw Error(fmt::format(
                "holds \"{}\" tiles; subscan reads EPT with LAZ tiles (\"laszip\") only",
                dataType));
        }
        const std::string hierarchyType = ept.value("hierarchyType", "json");
        if (hierarchyType != "json") {
            throw Error(fmt::format("has a \"{}\" hierarchy; subscan reads JSON hierarchies only",
                                    hierarchyType));
        }
        const std::vector<double> cube = ept.at("bounds").get<std::vector<double>>();
        const std::vector<double> conforming = ept.value("boundsConforming", cube);
        const double span = ept.at("span").get<double>();
        const auto finite = [](const std::vector<double>& values) {
            return values.size() == 6 && std::all_of(values.begin(), values.end(), [](double v) {
                       return std::abs(v) <= kMaxCoordinate;
                   });
        };
        if (!finite(cube) || !finite(conforming) || !(span >= 1.0 && span <= 1e9)) {
            throw Error(
                "has \"bounds\" or \"boundsConforming\" that are not 6 coordinates, or "
                "a \"span\" outside 1 to 1e9");
        }
        const glm::dvec3 min(cube[0], cube[1], cube[2]), max(cube[3], cube[4], cube[5]);
        const glm::dvec3 side = max - min;
        if (!(side.x > 0.0) || std::abs(side.x - side.y) > 1e-9 * side.x ||
            std::abs(side.x - side.z) > 1e-9 * side.x) {
            throw Error("has \"bounds\" that are not a cube");
        }
        description.cube = {0.5 * (min + max), 0.5 * side.x, side.x / span};
        description.bounds.add({conforming[0], conforming[1], conforming[2]});
        description.bounds.add({conforming[3], conforming[4], conforming[5]});
        description.points = ept.at("points").get<std::uint64_t>();
        description.version = ept.value("version", "1.0.0");
        if (const auto srs = ept.find("srs"); srs != ept.end() && srs->is_object()) {
            description.wkt = srs->value("wkt", "");
        }
    } catch (const nlohmann::json::exception& error) {
        throw Error(fmt::format("is not an EPT description ({})", error.what()));
    }
    return description;
}

EptHierarchyPage parseEptHierarchyPage(std::string_view text) {
    const nlohmann::json json = parseJson(text);
    if (!json.is_object()) {
        throw Error("is not an EPT hierarchy (a JSON object)");
    }
    EptHierarchyPage page;
    for (const auto& [name, count] : json.items()) {
        const std::optional<laz::VoxelKey> key = parseEptKey(name);
        if (!key || !count.is_number_integer()) {
            throw Error(fmt::format("the entry \"{}\" is not a key D-X-Y-Z with a count", name));
        }
        const auto points = count.get<std::int64_t>();
        if (points == -1) {
            page.pages.push_back(*key);
        } else if (points > 0) {
            page.nodes.push_back({*key, static_cast<std::uint64_t>(points)});
        } else if (points < -1) {
            throw Error(fmt::format("the entry \"{}\" has a count of {}", name, points));
        }
    }
    return page;
}

std::string nodeName(const laz::VoxelKey& key) {
    return fmt::format("node {}-{}-{}-{}", key.level, key.x, key.y, key.z);
}

std::size_t NodeSource::find(const laz::VoxelKey& key) const {
    if (key.level < 0 || key.level > kDeepestStreamedLevel || key.x < 0 || key.y < 0 || key.z < 0) {
        return nodes_.size();
    }
    const std::uint64_t packed = packedKey(key);
    const auto at = std::lower_bound(sortedKeys_.begin(), sortedKeys_.end(), packed);
    return at != sortedKeys_.end() && *at == packed
               ? static_cast<std::size_t>(at - sortedKeys_.begin())
               : nodes_.size();
}

void NodeSource::setNodes(std::vector<StreamedNode> nodes) {
    for (const StreamedNode& node : nodes) {
        const bool levelKnown = node.key.level >= 0 && node.key.level <= kDeepestStreamedLevel;
        const std::int32_t cells = std::int32_t{1} << (levelKnown ? node.key.level : 0);
        if (!levelKnown || node.key.x < 0 || node.key.y < 0 || node.key.z < 0 ||
            node.key.x >= cells || node.key.y >= cells || node.key.z >= cells) {
            throw Error(fmt::format("{}: {} lies outside the octree (levels 0 to {})", info_.name,
                                    nodeName(node.key), kDeepestStreamedLevel));
        }
    }
    std::sort(nodes.begin(), nodes.end(), [](const StreamedNode& a, const StreamedNode& b) {
        return packedKey(a.key) < packedKey(b.key);
    });
    for (std::size_t i = 1; i < nodes.size(); ++i) {
        if (packedKey(nodes[i].key) == packedKey(nodes[i - 1].key)) {
            throw Error(fmt::format("{}: {} is listed twice", info_.name, nodeName(nodes[i].key)));
        }
    }
    if (nodes.empty() || nodes.front().key.level != 0) {
        throw Error(fmt::format("{}: the octree has no root node with points", info_.name));
    }
    info_.points = 0;
    for (const StreamedNode& node : nodes) {
        info_.points += node.pointCount;
    }
    sortedKeys_.clear();
    for (const StreamedNode& node : nodes) {
        sortedKeys_.push_back(packedKey(node.key));
    }
    nodes_ = std::move(nodes);
}

bool isEpt(const std::filesystem::path& path) {
    std::error_code ignored;
    return path.filename() == "ept.json" ||
           std::filesystem::is_regular_file(path / "ept.json", ignored);
}

std::unique_ptr<NodeSource> openCopc(const std::filesystem::path& path) {
    try {
        return std::make_unique<CopcSource>(path);
    } catch (const Error& error) {
        throw Error(fmt::format("{}: {}", path.string(), error.what()));
    }
}

std::unique_ptr<NodeSource> openEpt(const std::filesystem::path& path) {
    return std::make_unique<EptSource>(path.filename() == "ept.json" ? path : path / "ept.json");
}

std::filesystem::path eptTilePath(const std::filesystem::path& folder, const laz::VoxelKey& key) {
    return folder / "ept-data" / fmt::format("{}-{}-{}-{}.laz", key.level, key.x, key.y, key.z);
}

LodMode parseLodMode(std::string_view name) {
    for (const auto& [mode, modeName] : kLodModeNames) {
        if (name == modeName) {
            return mode;
        }
    }
    throw Error(fmt::format("unknown level-of-detail mode \"{}\" (auto, on or off)", name));
}

std::unique_ptr<NodeSource> openStreamed(std::string_view source, LodMode mode) {
    if (mode == LodMode::Off) {
        return nullptr;
    }
    const std::filesystem::path path{std::string(source)};
    if (!source.starts_with("synthetic:")) {
        if (isEpt(path)) {
            return openEpt(path);
        }
        std::error_code ignored;
        if (std::filesystem::is_regular_file(path, ignored)) {
            // Only a LAS file's header and VLRs are read to tell.
            bool copc = false;
            try {
                const MappedFile file(path);
                ReadContext context;
                const LasHeader header = parseLasHeader(file.bytes(), file.bytes().size(), context);
                copc = findLasVlr(file.bytes(), header, "copc", 1).has_value();
            } catch (const Error&) {
                copc = false;  // not LAS at all: the whole-file readers say what it is
            }
            if (copc) {
                return openCopc(path);
            }
        }
    }
    std::error_code missing;
    if (mode == LodMode::On && !source.starts_with("synthetic:") &&
        !std::filesystem::exists(path, missing)) {
        throw Error(fmt::format("{}: no such file or folder", source));
    }
    if (mode == LodMode::On) {
        throw Error(fmt::format(
            "{}: is neither a COPC file nor an EPT dataset, which --lod on streams; index it "
            "first (subscan index), or load it whole with --lod auto or off",
            source));
    }
    return nullptr;
}

}  // namespace subscan::lod
