#include "io/PlyWriter.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <ostream>
#include <string>

#include <fmt/format.h>

#include "io/AtomicFile.h"

namespace subscan {

namespace {

static_assert(std::endian::native == std::endian::little,
              "the PLY writer copies values in memory order as binary_little_endian");

/// Relative rounding error of float coordinates we accept, as a fraction of the extent.
constexpr double kFloatErrorFraction = 1e-6;
/// Vertices per buffered write: a few megabytes.
constexpr std::size_t kVerticesPerChunk = 1 << 16;

template <class T>
void append(std::string& out, T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.append(bytes, sizeof(T));
}

std::string header(const PointCloud& cloud, bool doubles, bool alpha) {
    std::string text = "ply\nformat binary_little_endian 1.0\ncomment written by subscan\n";
    text += fmt::format("element vertex {}\n", cloud.size());
    const char* coordinateType = doubles ? "double" : "float";
    for (const char* axis : {"x", "y", "z"}) {
        text += fmt::format("property {} {}\n", coordinateType, axis);
    }
    if (cloud.hasColors()) {
        text += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
        if (alpha) {
            text += "property uchar alpha\n";
        }
    }
    if (cloud.hasNormals()) {
        text += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if (cloud.hasIntensities()) {
        text += "property float intensity\n";
    }
    if (!cloud.triangles.empty()) {
        text += fmt::format("element face {}\nproperty list uchar uint vertex_indices\n",
                            cloud.triangles.size());
    }
    text += "end_header\n";
    return text;
}

}  // namespace

bool plyNeedsDoubleCoordinates(const PointCloud& cloud) {
    if (cloud.size() == 0 || cloud.bounds.empty()) {
        return false;
    }
    const glm::dvec3 magnitude = glm::max(glm::abs(cloud.bounds.min), glm::abs(cloud.bounds.max));
    const double largest = std::max({magnitude.x, magnitude.y, magnitude.z});
    const glm::dvec3 extent = cloud.bounds.extent();
    const double size = std::max({extent.x, extent.y, extent.z});
    // Rounding to float moves a coordinate by up to half a float step at the largest magnitude.
    const double floatError =
        0.5 * largest * static_cast<double>(std::numeric_limits<float>::epsilon());
    return floatError > kFloatErrorFraction * size;
}

void writePly(const std::filesystem::path& path, const PointCloud& cloud) {
    const bool doubles = plyNeedsDoubleCoordinates(cloud);
    const bool alpha = std::any_of(cloud.colors.begin(), cloud.colors.end(),
                                   [](const Rgba8& color) { return color.a != 255; });
    writeFileAtomically(path, [&](std::ostream& stream) {
        const std::string head = header(cloud, doubles, alpha);
        stream.write(head.data(), static_cast<std::streamsize>(head.size()));
        std::string chunk;
        auto flush = [&] {
            stream.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
            chunk.clear();
        };
        for (std::size_t i = 0; i < cloud.size(); ++i) {
            const glm::dvec3 p = cloud.fileCoordinates(i);
            for (int axis = 0; axis < 3; ++axis) {
                if (doubles) {
                    append(chunk, p[axis]);
                } else {
                    append(chunk, static_cast<float>(p[axis]));
                }
            }
            if (cloud.hasColors()) {
                const Rgba8& color = cloud.colors[i];
                chunk.append({static_cast<char>(color.r), static_cast<char>(color.g),
                              static_cast<char>(color.b)});
                if (alpha) {
                    chunk.push_back(static_cast<char>(color.a));
                }
            }
            if (cloud.hasNormals()) {
                append(chunk, cloud.normals[i].x);
                append(chunk, cloud.normals[i].y);
                append(chunk, cloud.normals[i].z);
            }
            if (cloud.hasIntensities()) {
                append(chunk, cloud.intensities[i]);
            }
            if ((i + 1) % kVerticesPerChunk == 0) {
                flush();
            }
        }
        for (std::size_t t = 0; t < cloud.triangles.size(); ++t) {
            append(chunk, std::uint8_t{3});
            for (const std::uint32_t index : cloud.triangles[t]) {
                append(chunk, index);
            }
            if ((t + 1) % kVerticesPerChunk == 0) {
                flush();
            }
        }
        flush();
    });
}

}  // namespace subscan
