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
};

/// Whether the scan sampled a surface point (scene coordinates, with its unit outward normal).
using SampledTest = std::function<bool(const glm::dvec3& point, const glm::dvec3& normal)>;

/// Casts one ray through the centre of every pixel (what rasterizing the true surface samples)
/// and keeps the first hit. With `sampled`, also fills GroundTruthImages::sampled. Uses all
/// cores; deterministic.
GroundTruthImages renderGroundTruth(const Scene& scene, const Camera& camera,
                                    const SampledTest& sampled = {});

}  // namespace subscan
