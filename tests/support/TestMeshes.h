#pragma once

#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>

#include "core/PointCloud.h"

namespace subscan::test {

/// Concentric latitude-longitude spheres around `centre`, one closed triangle mesh per radius,
/// all in one cloud, every triangle wound counter-clockwise seen from outside its sphere.
inline PointCloud sphereMeshes(const std::vector<double>& radii, int stacks, int slices,
                               const glm::dvec3& centre = glm::dvec3(0.0)) {
    std::vector<glm::dvec3> vertices;
    std::vector<Triangle> triangles;
    for (const double radius : radii) {
        const auto first = static_cast<std::uint32_t>(vertices.size());
        auto index = [&](int stack, int slice) {
            // Stack 0 and `stacks` are the poles, one vertex each.
            if (stack == 0) {
                return first;
            }
            if (stack == stacks) {
                return first + 1 + static_cast<std::uint32_t>((stacks - 1) * slices);
            }
            return first + 1 + static_cast<std::uint32_t>((stack - 1) * slices + slice % slices);
        };
        vertices.push_back(centre + glm::dvec3(0.0, radius, 0.0));
        for (int stack = 1; stack < stacks; ++stack) {
            const double polar = std::numbers::pi * stack / stacks;
            for (int slice = 0; slice < slices; ++slice) {
                const double azimuth = 2.0 * std::numbers::pi * slice / slices;
                vertices.push_back(centre +
                                   radius * glm::dvec3(std::sin(polar) * std::cos(azimuth),
                                                       std::cos(polar),
                                                       std::sin(polar) * std::sin(azimuth)));
            }
        }
        vertices.push_back(centre - glm::dvec3(0.0, radius, 0.0));
        auto addOutward = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
            if (a == b || b == c || c == a) {
                return;  // the quads touching a pole are triangles
            }
            const glm::dvec3 normal =
                glm::cross(vertices[b] - vertices[a], vertices[c] - vertices[a]);
            const glm::dvec3 middle = (vertices[a] + vertices[b] + vertices[c]) / 3.0 - centre;
            if (glm::dot(normal, middle) < 0.0) {
                std::swap(b, c);
            }
            triangles.push_back({a, b, c});
        };
        for (int stack = 0; stack < stacks; ++stack) {
            for (int slice = 0; slice < slices; ++slice) {
                const std::uint32_t a = index(stack, slice), b = index(stack + 1, slice);
                const std::uint32_t c = index(stack + 1, slice + 1), d = index(stack, slice + 1);
                addOutward(a, b, c);
                addOutward(a, c, d);
            }
        }
    }
    PointCloudBuilder builder({}, vertices.size(), true);
    for (const glm::dvec3& vertex : vertices) {
        PointRecord record;
        record.position = vertex;
        builder.add(record);
    }
    for (const Triangle& triangle : triangles) {
        builder.addTriangle(triangle);
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

}  // namespace subscan::test
