#pragma once

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
};

/// Casts one ray through the centre of every pixel (what rasterizing the true surface samples)
/// and keeps the first hit. Uses all cores; deterministic.
GroundTruthImages renderGroundTruth(const Scene& scene, const Camera& camera);

}  // namespace subscan
