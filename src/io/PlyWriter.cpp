#include "io/PlyWriter.h"

#include <string>

#include <fmt/format.h>

#include "io/AtomicFile.h"
#include "io/WriterSupport.h"

namespace subscan {

namespace {

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

void writePly(const std::filesystem::path& path, const PointCloud& cloud) {
    const bool doubles = needsDoubleCoordinates(cloud);
    const bool alpha = hasTranslucentColors(cloud);
    writeFileAtomically(path, [&](std::ostream& stream) {
        ChunkedOutput out(stream);
        out.buffer() = header(cloud, doubles, alpha);
        for (std::size_t i = 0; i < cloud.size(); ++i) {
            out.appendPosition(cloud.fileCoordinates(i), doubles);
            if (cloud.hasColors()) {
                const Rgba8& color = cloud.colors[i];
                out.buffer().append({static_cast<char>(color.r), static_cast<char>(color.g),
                                     static_cast<char>(color.b)});
                if (alpha) {
                    out.buffer().push_back(static_cast<char>(color.a));
                }
            }
            if (cloud.hasNormals()) {
                out.append(cloud.normals[i].x);
                out.append(cloud.normals[i].y);
                out.append(cloud.normals[i].z);
            }
            if (cloud.hasIntensities()) {
                out.append(cloud.intensities[i]);
            }
            out.flushIfFull();
        }
        for (const Triangle& triangle : cloud.triangles) {
            out.append(std::uint8_t{3});
            for (const std::uint32_t index : triangle) {
                out.append(index);
            }
            out.flushIfFull();
        }
        out.flush();
    });
}

}  // namespace subscan
