#include "io/PcdWriter.h"

#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/AtomicFile.h"
#include "io/WriterSupport.h"

namespace subscan {

namespace {

struct Field {
    const char* name;
    int size;
    char type;
};

/// The header; the fields in the order writePcd writes their values.
std::string header(const PointCloud& cloud, bool doubles, const glm::dvec3& viewpoint) {
    const int coordinateSize = doubles ? 8 : 4;
    std::vector<Field> fields{
        {"x", coordinateSize, 'F'}, {"y", coordinateSize, 'F'}, {"z", coordinateSize, 'F'}};
    if (cloud.hasColors()) {
        fields.push_back({"rgb", 4, 'U'});
    }
    if (cloud.hasIntensities()) {
        fields.push_back({"intensity", 4, 'F'});
    }
    if (cloud.hasNormals()) {
        fields.insert(fields.end(),
                      {{"normal_x", 4, 'F'}, {"normal_y", 4, 'F'}, {"normal_z", 4, 'F'}});
    }
    std::string names, sizes, types, counts;
    for (const Field& field : fields) {
        names += fmt::format(" {}", field.name);
        sizes += fmt::format(" {}", field.size);
        types += fmt::format(" {}", field.type);
        counts += " 1";
    }
    return fmt::format(
        "# .PCD v0.7 - Point Cloud Data file format (written by subscan)\n"
        "VERSION 0.7\nFIELDS{}\nSIZE{}\nTYPE{}\nCOUNT{}\nWIDTH {}\nHEIGHT 1\n"
        "VIEWPOINT {:.17g} {:.17g} {:.17g} 1 0 0 0\nPOINTS {}\nDATA binary\n",
        names, sizes, types, counts, cloud.size(), viewpoint.x, viewpoint.y, viewpoint.z,
        cloud.size());
}

}  // namespace

void writePcd(const std::filesystem::path& path, const PointCloud& cloud,
              std::optional<glm::dvec3> viewpoint) {
    const bool doubles = needsDoubleCoordinates(cloud);
    writeFileAtomically(path, [&](std::ostream& stream) {
        ChunkedOutput out(stream);
        out.buffer() = header(cloud, doubles, viewpoint.value_or(glm::dvec3(0.0)));
        for (std::size_t i = 0; i < cloud.size(); ++i) {
            out.appendPosition(cloud.fileCoordinates(i), doubles);
            if (cloud.hasColors()) {
                const Rgba8& color = cloud.colors[i];
                out.append(static_cast<std::uint32_t>(color.r << 16 | color.g << 8 | color.b));
            }
            if (cloud.hasIntensities()) {
                out.append(cloud.intensities[i]);
            }
            if (cloud.hasNormals()) {
                out.append(cloud.normals[i].x);
                out.append(cloud.normals[i].y);
                out.append(cloud.normals[i].z);
            }
            out.flushIfFull();
        }
        out.flush();
    });
}

}  // namespace subscan
