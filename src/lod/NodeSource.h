#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/PointCloud.h"
#include "io/laz/Copc.h"
#include "lod/OctreeIndexer.h"

// Surveys stored as octrees whose nodes can be read one by one (COPC files, EPT datasets): what
// a level-of-detail renderer selects from. A node at level L holds points spread at the
// spacing rootSpacing / 2^L; the union of levels 0..L is a sample at that spacing, and the
// deepest nodes hold whatever their ancestors did not take.
namespace subscan::lod {

/// One node of a streamed octree: its voxel key and how many points it holds (> 0).
struct StreamedNode {
    laz::VoxelKey key;
    std::uint64_t pointCount = 0;
};

/// What every node source describes besides its nodes.
struct NodeSourceInfo {
    std::string name;          // the file or folder, for sentences
    std::string format;        // "las": LoadedScan::format of LAS-family data (COPC, EPT)
    std::string formatDetail;  // e.g. "EPT 1.0.0 (LAZ tiles), octree of 4 levels, 13 nodes"
    OctreeCube cube;           // the octree's cube and root spacing
    Bounds bounds;             // of every point, as the header (or EPT's source list) says
    std::uint64_t points = 0;  // in all nodes
    std::string wkt;           // the coordinate system where the source gives one (EPT's srs)
    /// What was left out when opening (a hierarchy page that cannot be read), one sentence
    /// each, naming the source's part but not the source.
    std::vector<std::string> warnings;
};

/// An octree of nodes, read node by node.
class NodeSource {
  public:
    virtual ~NodeSource() = default;
    const NodeSourceInfo& info() const { return info_; }
    /// Every node that holds points, parents before children (by level, then key).
    std::span<const StreamedNode> nodes() const { return nodes_; }
    /// The index in nodes() of the node with this key, or nodes().size() where there is none.
    std::size_t find(const laz::VoxelKey& key) const;
    /// The points of nodes()[index] (positions relative to the cloud's own origin, as readers
    /// make them). Safe from several threads at once. Throws subscan::Error with a sentence
    /// that names the node (not the source: callers do): a missing or truncated tile, a count
    /// other than the hierarchy's.
    virtual PointCloud load(std::size_t index) const = 0;

  protected:
    /// Sorts `nodes` parents first and keeps them.
    void setNodes(std::vector<StreamedNode> nodes);
    NodeSourceInfo info_;

  private:
    std::vector<StreamedNode> nodes_;
    std::vector<std::uint64_t> sortedKeys_;  // packed keys of nodes_, for find()
};

/// "node 2-1-0-3" of a source, for sentences.
std::string nodeName(const laz::VoxelKey& key);

/// Opens a COPC file: its header and hierarchy now, each node's points when loaded.
std::unique_ptr<NodeSource> openCopc(const std::filesystem::path& path);

/// Opens an EPT dataset (Entwine Point Tiles 1.0): `path` is its ept.json or the folder that
/// holds it. Tiles must be LAZ ("dataType": "laszip"); binary and zstd tiles are refused with
/// one sentence, as are hierarchies other than JSON.
std::unique_ptr<NodeSource> openEpt(const std::filesystem::path& path);

/// The LAZ tile of an EPT dataset's node: FOLDER/ept-data/LEVEL-X-Y-Z.laz.
std::filesystem::path eptTilePath(const std::filesystem::path& folder, const laz::VoxelKey& key);

/// What an EPT dataset's ept.json says: the octree's cube (`bounds`) and root spacing (its side
/// over `span`), the points' bounds (`boundsConforming`), their count and the version.
struct EptDescription {
    OctreeCube cube;
    Bounds bounds;
    std::uint64_t points = 0;
    std::string version;
    std::string wkt;  // "srs": {"wkt": ...}, where it is given
};
/// Parses ept.json's text. Throws subscan::Error (without the file's name) for what is not an
/// EPT description, for tiles other than LAZ and for hierarchies other than JSON.
EptDescription parseEptDescription(std::string_view text);

/// One page of an EPT hierarchy (ept-hierarchy/D-X-Y-Z.json): the nodes with points, and the
/// nodes whose counts lie in pages of their own (a count of -1).
struct EptHierarchyPage {
    std::vector<StreamedNode> nodes;
    std::vector<laz::VoxelKey> pages;
};
/// Parses a hierarchy page's text. Throws subscan::Error (without the file's name).
EptHierarchyPage parseEptHierarchyPage(std::string_view text);

/// Whether `path` names an EPT dataset (an ept.json, or a folder holding one).
bool isEpt(const std::filesystem::path& path);

/// Whether a scan is streamed by its levels of detail (`--lod`): `auto`
/// streams COPC files and EPT datasets and loads everything else whole, `on` refuses what
/// cannot be streamed, `off` loads every file whole.
enum class LodMode { Auto, On, Off };
/// Each mode's name, as `--lod` and the settings file's streaming.lod spell it.
inline constexpr std::pair<LodMode, std::string_view> kLodModeNames[] = {
    {LodMode::Auto, "auto"},
    {LodMode::On, "on"},
    {LodMode::Off, "off"},
};
/// "auto", "on" or "off"; throws subscan::Error for anything else.
LodMode parseLodMode(std::string_view name);

/// The source `source` (a path, or "synthetic:...") streams from under `mode`, or nullptr where
/// it is loaded whole. Throws subscan::Error naming the source where it cannot be opened, or
/// with `on` where it is neither COPC nor EPT.
std::unique_ptr<NodeSource> openStreamed(std::string_view source, LodMode mode);

}  // namespace subscan::lod
