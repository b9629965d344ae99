#include "eval/GroundTruth.h"

#include <algorithm>
#include <limits>
#include <thread>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

namespace subscan {

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
                             std::vector<std::uint8_t>(sampled ? pixels : 0, 0)};
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
                images.normals[i] = glm::vec3(glm::normalize(rotation * hit->normal));
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
