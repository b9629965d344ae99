#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/Camera.h"
#include "core/KdTree.h"
#include "core/LocalSpacing.h"
#include "core/PointCloud.h"
#include "eval/GroundTruth.h"
#include "eval/Metrics.h"
#include "gpu/GlContext.h"
#include "render/RenderSettings.h"
#include "scan/Scene.h"
#include "scan/VirtualScanner.h"

namespace subscan {

/// How `subscan eval` looks at a scene: `views` cameras on an orbit around it (yaw spread over
/// 360°, pitch alternating between +25° and -15°), auto-framed like `subscan render`.
struct EvaluationSettings {
    int views = 8;
    int width = 1024;
    int height = 1024;
    double fovyDegrees = 45.0;
    /// Eye distance from the centre, scene units (close-ups); unset, the view frames the scene.
    std::optional<double> distance;
    int smallestSplat = 2;  // the splats baseline reports the best size in this range
    int largestSplat = 8;
    /// When set, each view's pictures go here: truth.png and surface.png (shaded), coverage.png
    /// (grey: both, red: missed, blue: leaked, yellow: a surface behind the true one shows
    /// through) and normal_error.png (black 0° to white 45°). With --temporal, each frame's
    /// frameNNNN_{truth,points,surface,temporal,supersampled}.png (the truth supersampled).
    std::filesystem::path exportDirectory;
    /// When not empty, the views instead of the orbit (`views` is then ignored).
    std::vector<OrbitView> viewpoints;
    /// When set (adaptToScanner), the scanner's view turned `degrees` of azimuth on from the
    /// first of `viewpoints`: the path eval --temporal follows instead of the orbit.
    std::function<OrbitView(double degrees)> scannerView;
    /// When set, which true surface points the scan could sample: coverage and leakage count
    /// only those (DESIGN.md §7: coverage is of the ground truth the scan sampled).
    SampledTest sampled;
    /// Judge occlusion errors by the scan's local spacing where the true surface is (the
    /// nearest point's, the larger of its spacing and its gap across scan lines, at least h)
    /// instead of h alone: a LiDAR scan's far rings lie tens of h apart, and the fill between
    /// them is off the plane by a share of that gap without anything showing through.
    bool occlusionsByLocalSpacing = false;
    /// When set, the surface is reconstructed as a streamed survey is: the points are indexed
    /// into a COPC file in a temporary folder, and each view loads the nodes it selects within
    /// this budget (lod::selectNodes), with the renderer's spacing and normals for them as
    /// `render` makes them. The points and splats baselines still draw every point.
    std::optional<std::uint64_t> pointBudget;
};

/// Where the views of a LiDAR scan's evaluation stand: near its scanner (ViewsFrom::Scanner),
/// or on an orbit around the whole scene (ViewsFrom::Orbit), where a station's sparse far
/// surfaces stand in front of its dense near ground.
enum class ViewsFrom { Scanner, Orbit };

/// Fits `settings` to a scan made with `scanner` of `scene` (DESIGN.md §7, real scans). Object
/// scans keep the orbit. A station sees only what is visible from where it stands, so its
/// `views` views stand 1 m above and 1 m behind the station, look out in azimuths 45 degrees
/// plus equal turns, 10 degrees down; an airborne strip's look down at 45 degrees from the
/// orbit's usual distance, in the same azimuths. With ViewsFrom::Orbit both instead look down
/// at 30 degrees from the orbit's distance, in those azimuths. All count only surfaces the
/// scan could sample (scannerCanSample): the backs of buildings, the ground behind a wall,
/// walls parallel to the flight's scan planes are no reconstruction's to fill; occlusion errors
/// are judged by the local spacing (occlusionsByLocalSpacing). `scene` must outlive
/// `settings`. Also sets `scannerView`, so that eval --temporal turns at the station
/// (or about the scene) instead of orbiting it at the object scans' angles.
void adaptToScanner(EvaluationSettings& settings, const Scene& scene,
                    const ScannerSettings& scanner, ViewsFrom viewsFrom = ViewsFrom::Scanner);

/// The scan's local spacing (scene units) where each pixel's true surface is, for
/// GroundTruthImages::spacing: that of the nearest scan point, the larger of its spacing w and
/// its gap across scan lines (estimateLocalSpacing) times h; h everywhere where the local
/// spacing is not estimated. `points` and `spacing` must outlive it.
class SpacingAtTruth {
  public:
    SpacingAtTruth(const PointCloud& points, const PointSpacing& spacing);
    /// Per pixel of `truth` seen by `camera` (h where it shows nothing).
    std::vector<float> at(const Camera& camera, const GroundTruthImages& truth) const;

  private:
    const PointCloud& points_;
    const PointSpacing& spacing_;
    PositionsAdaptor adaptor_;
    KdTree tree_;
};

/// DESIGN.md §7 metrics of each method, averaged over the views.
struct EvaluationReport {
    int views = 0;
    int width = 0;
    int height = 0;
    std::size_t points = 0;
    double spacing = 0.0;
    QualityMetrics points1px;
    QualityMetrics splats;
    int splatSize = 0;  // the best splat size in pixels (by PSNR)
    QualityMetrics surface;
    int surfaceReducedViews = 0;  // views the surface reconstructed at reduced resolution
    double surfacePoints = 0.0;   // with a point budget: the points a view loaded, on average
};

/// Renders `points` with each method and compares with `truth` seen by the same cameras.
/// Points and splats have no normals: they are shaded flat (normal towards the eye) with the same
/// lights, which is what a point viewer shows; the surface uses its reconstructed normals; the
/// ground truth its exact ones. `render` holds the surface and shading settings.
EvaluationReport evaluate(GlContext& context, const Scene& truth, const PointCloud& points,
                          const EvaluationSettings& settings, const RenderSettings& render);

/// How `subscan eval --temporal` moves: `frames` cameras on a slow orbit (yaw from 20° in steps
/// of `stepDegrees`, pitch 25°), of EvaluationSettings' size, lens and distance.
struct TemporalEvaluationSettings {
    int frames = 24;
    double stepDegrees = 1.0;
    int supersampling = 4;  // ground-truth rays per pixel and side
    // Frames the filtered sequence converges over at its first pose, and the converged
    // sequence (surfaceSupersampled) at every pose.
    int stillSamples = 16;
};

/// DESIGN.md §7's temporal measures per method, against the supersampled truth.
struct TemporalReport {
    int frames = 0;
    double stepDegrees = 0.0;
    int width = 0;
    int height = 0;
    int supersampling = 0;
    std::size_t points = 0;
    double spacing = 0.0;
    /// With a point budget: the points of the one set of nodes the surface drew for every frame.
    std::size_t surfacePoints = 0;
    TemporalMetrics points1px;
    TemporalMetrics splats;
    float splatSize = 0.0f;  // RasterSettings::pointSize
    TemporalMetrics surface;
    TemporalMetrics surfaceTemporal;  // one continuous sequence through the temporal filter
    // The surface converged afresh at every pose (stillSamples jittered frames): what a temporal
    // filter that anti-aliases without lag or blur would show. A filter that blurred more
    // could change less from frame to frame, but only by losing detail the truth has.
    TemporalMetrics surfaceSupersampled;
    // The first pose as a still: one frame of the surface, and the filter's converged picture.
    double stillPsnrSurfaceDb = 0.0;
    double stillPsnrTemporalDb = 0.0;
};

/// Renders the orbit with each method (the temporal filter's sequence starting converged) and
/// compares the sequences with the truth's, supersampled. With settings.pointBudget the surface
/// is streamed as `bench` and `turntable` stream it: one set of nodes for the whole orbit
/// (lod::selectNodes over every frame's camera), as the viewer keeps its nodes while the camera
/// moves and loads a view's own only once it rests; the baselines draw every point.
TemporalReport evaluateTemporal(GlContext& context, const Scene& truth, const PointCloud& points,
                                const EvaluationSettings& settings,
                                const TemporalEvaluationSettings& temporal,
                                const RenderSettings& render);

nlohmann::json toJson(const TemporalReport& report);

/// {"views", "width", "height", "points", "spacing", "methods": {"points", "splats",
/// "surface"}} with the keys of each method named in the issue (snake case).
nlohmann::json toJson(const EvaluationReport& report);

}  // namespace subscan
