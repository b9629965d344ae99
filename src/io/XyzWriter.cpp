#include "io/XyzWriter.h"

#include <iterator>
#include <string>

#include <fmt/format.h>

#include "io/AtomicFile.h"
#include "io/WriterSupport.h"

namespace subscan {

void writeXyz(const std::filesystem::path& path, const PointCloud& cloud) {
    writeFileAtomically(path, [&](std::ostream& stream) {
        ChunkedOutput out(stream);
        std::string& text = out.buffer();
        text = "X Y Z";
        if (cloud.hasColors()) {
            text += " Red Green Blue";
        }
        if (cloud.hasIntensities()) {
            text += " Intensity";
        }
        if (cloud.hasNormals()) {
            text += " NormalX NormalY NormalZ";
        }
        text += '\n';
        auto inserter = std::back_inserter(text);
        for (std::size_t i = 0; i < cloud.size(); ++i) {
            // fmt's "{}" is the shortest text that round-trips, and independent of the locale.
            const glm::dvec3 p = cloud.fileCoordinates(i);
            fmt::format_to(inserter, "{} {} {}", p.x, p.y, p.z);
            if (cloud.hasColors()) {
                const Rgba8& color = cloud.colors[i];
                fmt::format_to(inserter, " {} {} {}", color.r, color.g, color.b);
            }
            if (cloud.hasIntensities()) {
                fmt::format_to(inserter, " {}", cloud.intensities[i]);
            }
            if (cloud.hasNormals()) {
                const glm::vec3& n = cloud.normals[i];
                fmt::format_to(inserter, " {} {} {}", n.x, n.y, n.z);
            }
            text += '\n';
            out.flushIfFull();
        }
        out.flush();
    });
}

}  // namespace subscan
