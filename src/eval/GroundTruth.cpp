#include "eval/GroundTruth.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace subscan {

namespace {

/// GroundTruthImages::depthWithinPixel of the pixel whose centre's view direction (z = -1) is
/// `centre`, whose surface lies at linear depth `depth` with view-space normal `normal`: the
/// tangent plane n . p = n . (depth * centre) meets the ray through a corner, direction w with
/// w.z = -1, at linear depth (n . centre) * depth / (n . w).
double depthWithinPixel(const glm::dvec3& centre, double depth, const glm::dvec3& normal,
                        double focal) {
    const double cap = kSteepestDepthWithinPixel * depth / focal;
    const double facing = glm::dot(normal, centre);
    double farthest = 0.0;
    for (const double dx : {-0.5, 0.5}) {
        for (const double dy : {-0.5, 0.5}) {
            const double across = glm::dot(normal, centre + glm::dvec3(dx, dy, 0.0) / focal);
            // The plane turns away from (or runs along) the corner's ray: it reaches any depth.
            if (across * facing <= 0.0) {
                return cap;
            }
            farthest = std::max(farthest, std::abs(facing * depth / across - depth));
        }
    }
    return std::min(farthest, cap);
}

}  // namespace

GroundTruthImages renderGroundTruth(const Scene& scene, const Camera& camera,
                                    const SampledTest& sampled) {
    const int width = camera.width;
    const int height = camera.height;
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    GroundTruthImages images{width,
                             height,
                             std::vector<float>(pixels, std::numeric_limits<float>::infinity()),
                             std::vector<glm::vec3>(pixels, glm::vec3(0.0f)),
                             std::vector<glm::vec3>(pixels, glm::vec3(0.0f)),
                             std::vector<std::uint8_t>(sampled ? pixels : 0, 0),
                             {},
                             std::vector<float>(pixels, 0.0f)};
    const double focal = camera.focalLengthPixels();
    const glm::dmat4 toFile = glm::inverse(camera.view);
    const glm::dvec3 eye = camera.eye();
    const glm::dmat3 rotation(camera.view);
    const double maxDistance = 2.0 * camera.farPlane;

    auto renderRows = [&](int firstRow, int rowStep) {
        for (int y = firstRow; y < height; y += rowStep) {
            for (int x = 0; x < width; ++x) {
                const glm::dvec3 viewDirection = pixelCentreDirection(camera, x, y);
                Ray ray;
                ray.origin = eye;
                ray.direction = glm::normalize(glm::dvec3(toFile * glm::dvec4(viewDirection, 0.0)));
                const auto hit = scene.intersect(ray, maxDistance);
                if (!hit) {
                    continue;
                }
                const std::size_t i = static_cast<std::size_t>(y) * width + x;
                // Linear depth is the distance along -Z of view space.
                images.depth[i] = static_cast<float>(hit->distance / glm::length(viewDirection));
                const glm::dvec3 normal = glm::normalize(rotation * hit->normal);
                images.normals[i] = glm::vec3(normal);
                images.depthWithinPixel[i] = static_cast<float>(
                    depthWithinPixel(viewDirection, images.depth[i], normal, focal));
                images.albedo[i] = hit->albedo;
                if (sampled) {
                    images.sampled[i] =
                        sampled(ray.origin + hit->distance * ray.direction, hit->normal);
                }
            }
        }
    };
    const int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> workers;
    for (int t = 1; t < threads; ++t) {
        workers.emplace_back(renderRows, t, threads);
    }
    renderRows(0, threads);
    for (std::thread& worker : workers) {
        worker.join();
    }
    return images;
}

}  // namespace subscan
