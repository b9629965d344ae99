#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include <glm/vec4.hpp>

#include "core/PointCloud.h"
#include "core/Spacing.h"

namespace subscan {

/// The local spacing of DESIGN.md §4, for clouds whose density varies (LiDAR stations, depth
/// cameras, an airborne scan's canopy over its ground): per point, in units of the global
/// spacing h,
///   w    the spacing where the point is: the distance to the 4th nearest non-coincident
///        neighbour, its median over the point and its 4 nearest (a boundary point's own is
///        too large), scaled so that over the whole cloud its median is 1, and 1 where within
///        a factor 1.5 of that (an even scan's sampling noise);
///   xyz  where the point lies on a scan line whose neighbouring lines are more than twice w
///        away (far ground seen by a station comes as rings), the vector to the nearest point
///        across the line: the nearest neighbour more than 45 degrees off the line's direction
///        (the direction to the nearest neighbour); else 0.
/// The reconstruction takes, per pixel, the larger of w and the across vector projected into
/// the picture: an across gap seen end-on, as from the scanner itself, is small on screen.
/// Both are cut to kSparsestReach times the ratio all but the sparsest 0.1 % stay within
/// (cutTheSparsest).
/// `cancelled` (may be empty) is asked now and then, from any thread; once it says yes the
/// work stops and the result is incomplete.
/// The ratio (the larger of w and the across vector's length, in h) that all points of
/// `spacing` (estimateLocalSpacing's form) but the sparsest 0.1 % stay within, at least 1; 1
/// for none.
float sparseSpacingRatio(const std::vector<glm::vec4>& spacing);

/// No point's spacing reaches further than this many times the ratio (the larger of w and the
/// across vector's length) that all but the sparsest 0.1 % stay within. A cluster of stray
/// points far from the rest (three 8 cm from the Stanford dragon, whose points lie 0.3 mm
/// apart: 41 times it) filled a block hundreds of h wide; the sparsest ground of a LiDAR scan
/// reaches up to 7 times it (lone_star.laz: 85 against 12.2). A cut at the ratio itself took 5 %
/// of the lone star's surface, at 4 times 0.4 %, and left the dragon's cluster 28 pixels
/// instead of 2,100; at 8 times 104.
inline constexpr float kSparsestReach = 4.0f;
/// Cuts `spacing` (estimateLocalSpacing's form) so: an across vector along itself, w to the
/// bound. Before a streamed view's levels raise their points' w (withLevelSpacing), which
/// keeps coarse levels closed however few their points.
void cutTheSparsest(std::vector<glm::vec4>& spacing);

std::vector<glm::vec4> estimateLocalSpacing(const PointCloud& cloud, double h,
                                            const std::function<bool()>& cancelled = {});

/// Whether the cloud's spacing varies a lot: the 90th percentile of `sampledNearest`
/// (sampledNearestDistances) over its 10th above kVaryingSpacingRatio.
bool spacingVaries(std::vector<float> sampledNearest);

/// Even scans (range images, photogrammetry, synthetic object scans) stay below this ratio of
/// the 90th to the 10th percentile of nearest-neighbour distances; a station's points lie
/// 10-50 times farther apart at the edge of its range than next to it.
inline constexpr float kVaryingSpacingRatio = 6.0f;

/// Up to this many points the local spacing is estimated for every cloud (about two seconds on
/// two cores, bench/README.md): it changes little on even scans and much where density varies
/// moderately (an airborne scan's tree canopy against its ground). Larger clouds get it only when
/// their spacing varies a lot, as a station's does.
inline constexpr std::size_t kAlwaysLocalSpacingPoints = 2'000'000;

/// The spacing the renderer works with: h, and the local spacing (empty where not estimated).
struct PointSpacing {
    double global = 0.0;
    std::vector<glm::vec4> local;
};

/// h (`global` when given, else estimateSpacing) and the local spacing by the rule of
/// kAlwaysLocalSpacingPoints.
PointSpacing estimatePointSpacing(const PointCloud& cloud,
                                  std::optional<double> global = std::nullopt);
/// The same from sampleSpacing's result: its distances decide whether a large cloud's
/// spacing varies, so that no second search is needed.
/// `cancelled` as estimateLocalSpacing takes it.
PointSpacing estimatePointSpacing(const PointCloud& cloud, const SpacingSample& sample,
                                  const std::function<bool()>& cancelled = {});
/// A streamed view's (LoadedScan::levelSpacing, one per point, or empty: the same as above):
/// each point's w is at least its level's spacing over that of the level most points lie on,
/// times the lower quartile of those points' estimates (1 without estimates, for clouds above
/// kAlwaysLocalSpacingPoints of even spacing, which then get a local spacing). A coarse level's
/// points lie that much farther apart whatever their nearest neighbours say: where a finer
/// level's nodes border on it, its points near the border find neighbours of the finer level,
/// and the fill's expected gap there was the finer level's (holes along the border,
/// StreamedSurfaceGLTest). Level spacing 0 sets no minimum.
PointSpacing estimatePointSpacing(const PointCloud& cloud, std::span<const float> levelSpacing);
/// That raise applied to an estimate of the same points (`spacing`: estimatePointSpacing's, its
/// local spacing one entry per point or empty). Throws std::invalid_argument where the counts
/// differ.
PointSpacing withLevelSpacing(PointSpacing spacing, std::span<const float> levelSpacing);

}  // namespace subscan
