#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <glm/vec3.hpp>

#include "core/Camera.h"
#include "scan/Scene.h"

namespace subscan {

/// Per-pixel images of an exact surface seen by a camera, rows top first: linear depth (+inf
/// where the pixel's ray misses), view-space unit normals and linear albedo.
struct GroundTruthImages {
    int width = 0;
    int height = 0;
    std::vector<float> depth;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec3> albedo;
    /// 1 where the pixel's surface point is one the scan could sample, else 0 (see
    /// scannerCanSample); empty when every point could be. Metrics skip unsampled pixels.
    std::vector<std::uint8_t> sampled;
    /// The scan's spacing at each pixel's true surface point (scene units), where the
    /// evaluation judges occlusions by it (EvaluationSettings::occlusionsByLocalSpacing); empty
    /// when h is the scale everywhere.
    std::vector<float> spacing;
    /// How far the true surface's depth reaches from the pixel centre's within the pixel: the
    /// largest |depth - centre depth| of its tangent plane at the pixel's four corners, at most
    /// kSteepestDepthWithinPixel pixel widths at that depth. A reconstruction sampled anywhere in
    /// the pixel (a point's own depth) is off the centre's by up to this without any surface
    /// behind showing through; 0 where the pixel holds no surface.
    std::vector<float> depthWithinPixel;
};

/// The cap of GroundTruthImages::depthWithinPixel, in pixel widths at the pixel's depth: what
/// the steepest surface the reconstruction keeps whole takes within half a pixel. The pull keeps
/// those of a texel's 4x4 children within SurfaceSettings::pullDepthSlope (8) of its texel
/// widths behind the front-most; the children's centres span 1.5 texel widths, so a surface
/// rising up to 8 / 1.5 = 16/3 pixel widths a pixel keeps all of them (79 degrees from facing
/// the eye), and half a pixel spans 8/3. Steeper, the pull cuts it, and a grazing plane's
/// corners would lie at any depth.
inline constexpr double kSteepestDepthWithinPixel = 8.0 / 3.0;

/// Whether the scan sampled a surface point (scene coordinates, with its unit outward normal).
using SampledTest = std::function<bool(const glm::dvec3& point, const glm::dvec3& normal)>;

/// Casts one ray through the centre of every pixel (what rasterizing the true surface samples)
/// and keeps the first hit. With `sampled`, also fills GroundTruthImages::sampled. Uses all
/// cores; deterministic.
GroundTruthImages renderGroundTruth(const Scene& scene, const Camera& camera,
                                    const SampledTest& sampled = {});

}  // namespace subscan
