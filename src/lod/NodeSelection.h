#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "core/Camera.h"
#include "core/PointCloud.h"
#include "io/ScanLoader.h"
#include "lod/NodeSource.h"

namespace subscan::lod {

/// Children are loaded while their parent's spacing, seen from the camera where the child lies
/// nearest, is at least this many pixels: below it the parent's points already lie closer
/// together than pixels, and the children would add points, not detail.
inline constexpr double kFinestParentSpacingPixels = 0.5;

/// Points a view loads without --point-budget, where the renderer is Mesa's llvmpipe and where
/// it is a GPU. On llvmpipe 1 M points cost about what the Happy Buddha's 1.1 M do (160 ms a
/// 1080p surface frame, bench/README.md), and what the renderer estimates at load (local
/// spacing, normals) takes a few seconds for them. The GPU's is a placeholder until measured.
inline constexpr std::uint64_t kSoftwarePointBudget = 1'000'000;
inline constexpr std::uint64_t kHardwarePointBudget = 10'000'000;

/// `requested`, or where it is 0 the default of the renderer (`software`: Mesa's llvmpipe).
inline std::uint64_t pointBudgetFor(std::uint64_t requested, bool software) {
    return requested != 0 ? requested : software ? kSoftwarePointBudget : kHardwarePointBudget;
}

/// The nodes `camera` shows within `pointBudget` points, as Potree chooses them: from the root,
/// the node that looks largest next (its bounding sphere's radius in pixels; the node holding
/// the eye first), skipping nodes outside the view and children that add no detail
/// (kFinestParentSpacingPixels), until the next node does not fit the budget. The root is
/// always taken. Parents come before their children; the same view gives the same nodes.
/// Indices into source.nodes().
std::vector<std::size_t> selectNodes(const NodeSource& source, const Camera& camera,
                                     std::uint64_t pointBudget);
/// The same for several views at once (a turntable's frames): a node is in view where any
/// view shows it, as large as the largest view shows it, and its children add detail where
/// they do in any view. One set for every view, so that nothing pops from frame to frame.
std::vector<std::size_t> selectNodes(const NodeSource& source, std::span<const Camera> cameras,
                                     std::uint64_t pointBudget);

/// The nodes of the levels from the root down, while they hold at most `points` in all (at
/// least the root): a view-independent sample of the whole survey, to frame it by.
std::vector<std::size_t> topLevels(const NodeSource& source, std::uint64_t points);

/// Points of a streamed source's overview (topLevels): framingBounds samples as many.
inline constexpr std::uint64_t kOverviewPoints = 200'000;

/// `nodes` of `source` as a loaded scan (loadNodes on every core), with the whole survey's
/// bounds (a view is framed, and coloured by height, alike whatever its nodes), each point's
/// LoadedScan::levelSpacing, the source's format, and warnings: the source's own
/// (`withSourceWarnings`: once per opening) and those of the nodes left out. Throws
/// subscan::Error naming the source where none of `nodes` could be read (an empty picture
/// would pass for an empty view).
LoadedScan loadStreamedScan(const NodeSource& source, std::span<const std::size_t> nodes,
                            bool withSourceWarnings = true,
                            const std::function<bool()>& cancelled = {});

/// The overview a streamed source opens with: its top levels (topLevels, kOverviewPoints),
/// with the source's warnings. Where none of them can be read (a missing root tile), the next
/// level down joins them, and so on: only a source none of whose nodes can be read is an error.
/// `nodes` (may be null) receives the nodes it holds.
LoadedScan loadStreamedOverview(const NodeSource& source,
                                std::vector<std::size_t>* nodes = nullptr);

/// Loads `nodes` on `threads` threads (0: every core) into one cloud, in the order given, its
/// positions about the middle of the source's bounds. A node that cannot be read is left out
/// with one warning that names the node (the caller names the source); the rest still shows.
/// `cancelled` (may be empty) is asked before each node: once true, the rest are left out.
/// `read` (may be null) receives the nodes whose points the cloud holds, in the order given.
PointCloud loadNodes(const NodeSource& source, std::span<const std::size_t> nodes,
                     std::vector<std::string>& warnings, unsigned threads = 0,
                     const std::function<bool()>& cancelled = {},
                     std::vector<std::size_t>* read = nullptr);

}  // namespace subscan::lod
