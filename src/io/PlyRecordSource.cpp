#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/InputFile.h"
#include "io/PlyHeader.h"
#include "io/RecordSourceSupport.h"

// Binary PLY vertices as records, read in pieces: a first pass finds the bounds (a PLY header
// has none), which choose the quantization, and the colour's scale; each read then converts
// the next vertices.
namespace subscan {

namespace {

/// Header bytes read at first; a longer header is read again with four times as many.
constexpr std::size_t kFirstHeaderBytes = 64 * 1024;
/// No real header comes near this: a file without end_header within it is not PLY.
constexpr std::size_t kLargestHeaderBytes = 16u << 20;
/// Vertices read from the file at once (a few MiB for wide vertices).
constexpr std::size_t kVerticesPerBlock = 1 << 16;

std::uint16_t colorWord(double value, PlyColorScale scale) {
    switch (scale) {
        case PlyColorScale::Byte:
            return colorWordFromByte(value);
        case PlyColorScale::Word:
            return colorWordFromWord(value);
        case PlyColorScale::Unit:
            return colorWordFromUnit(value);
    }
    return 0;
}

/// Where each vertex property lies in a vertex, and how to read it.
struct VertexAccess {
    std::vector<std::size_t> offsets;
    std::vector<PlyType> types;
    bool bigEndian = false;

    double value(const std::byte* vertex, std::size_t property) const {
        return loadPlyValue(types[property], bigEndian, vertex + offsets[property]);
    }
};

/// The file's start up to and including the end_header line, or all of a shorter file.
std::string readHeaderText(const InputFile& file) {
    std::string text;
    for (std::size_t size = kFirstHeaderBytes;; size *= 4) {
        text.resize(static_cast<std::size_t>(std::min<std::uint64_t>(size, file.size())));
        file.read(0, std::as_writable_bytes(std::span(text)));
        if (text.find("end_header") != std::string::npos || text.size() == file.size() ||
            size >= kLargestHeaderBytes) {
            return text;
        }
    }
}

class PlyRecordSource final : public ConvertedRecordSource {
  public:
    PlyRecordSource(InputFile file, std::string name, const PlyHeader& header,
                    const PlyElement& vertex, std::uint64_t vertexOffset, std::size_t stride)
        : file_(std::move(file)),
          vertexCount_(vertex.count),
          vertexOffset_(vertexOffset),
          stride_(stride),
          layout_(findPlyVertexLayout(vertex)) {
        access_.bigEndian = header.encoding == PlyEncoding::BinaryBigEndian;
        std::size_t offset = 0;
        for (const PlyProperty& property : vertex.properties) {
            access_.offsets.push_back(offset);
            access_.types.push_back(property.type);
            offset += plySizeOf(property.type);
        }
        // The first pass, over every vertex, also tells how to read the colour, as the
        // whole-file reader decides it.
        bool largeColorValues = false;
        bool intensitiesFit = true;
        const Bounds bounds = findBounds(vertex, largeColorValues, intensitiesFit);
        if (layout_.color) {
            for (int k = 0; k < 3; ++k) {
                colorScales_[k] =
                    plyColorScale(access_.types[(*layout_.color)[k]], largeColorValues);
            }
        }
        std::vector<std::string> warnings;
        for (const PlyElement& element : header.elements) {
            if (element.name == "face" && element.count > 0) {
                warnings.push_back(facesNotKept(name, element.count));
            }
        }
        if (!intensitiesFit) {
            warnings.push_back(intensitiesNotKept(name));
        }
        // Binary values have no decimals to keep (PointCloud::coordinateStep).
        startRecords(std::move(name), vertexCount_, layout_.color.has_value(),
                     layout_.normal.has_value(), bounds, 0.0, std::move(warnings));
    }

    std::size_t read(std::vector<std::byte>& records, std::size_t maxPoints) override {
        try {
            const auto count = static_cast<std::size_t>(
                std::min<std::uint64_t>(maxPoints, vertexCount_ - nextVertex_));
            records.reserve(records.size() + count * info().format.recordLength());
            forEachVertex(nextVertex_, count, [&](const std::byte* vertex, std::uint64_t) {
                writer().append(records, point(vertex));
            });
            nextVertex_ += count;
            return count;
        } catch (const Error& error) {
            throwNamed(info().name, error);
        }
    }

    void rewind() override { nextVertex_ = 0; }

  private:
    template <class Visit>
    void forEachVertex(std::uint64_t first, std::size_t count, Visit&& visit) {
        for (std::size_t done = 0; done < count;) {
            const std::size_t block = std::min(kVerticesPerBlock, count - done);
            block_.resize(block * stride_);
            file_.read(vertexOffset_ + (first + done) * stride_, block_);
            for (std::size_t i = 0; i < block; ++i) {
                visit(block_.data() + i * stride_, first + done + i);
            }
            done += block;
        }
    }

    glm::dvec3 position(const std::byte* vertex) const {
        return {access_.value(vertex, layout_.position[0]),
                access_.value(vertex, layout_.position[1]),
                access_.value(vertex, layout_.position[2])};
    }

    /// Also sets `largeColorValues` when a colour value is large (isLargePlyColorValue), and
    /// clears `intensitiesFit` when an intensity does not fit LAS's (fitsIntensityWord).
    Bounds findBounds(const PlyElement& vertex, bool& largeColorValues, bool& intensitiesFit) {
        const std::vector<std::size_t> colorChannels = layout_.colorChannels();
        Bounds bounds;
        forEachVertex(0, static_cast<std::size_t>(vertexCount_),
                      [&](const std::byte* data, std::uint64_t index) {
                          const glm::dvec3 p = position(data);
                          for (int axis = 0; axis < 3; ++axis) {
                              if (!std::isfinite(p[axis])) {
                                  throw Error(fmt::format(
                                      "the PLY vertex {} of {} has the {} coordinate {} ('{}'); "
                                      "LAS records need finite coordinates",
                                      index + 1, vertexCount_, "xyz"[axis], p[axis],
                                      vertex.properties[layout_.position[axis]].name));
                              }
                          }
                          bounds.add(p);
                          for (const std::size_t c : colorChannels) {
                              largeColorValues =
                                  largeColorValues ||
                                  isLargePlyColorValue(access_.types[c], access_.value(data, c));
                          }
                          if (layout_.intensity) {
                              intensitiesFit = intensitiesFit && fitsIntensityWord(access_.value(
                                                                     data, *layout_.intensity));
                          }
                      });
        return bounds;
    }

    ConvertedPoint point(const std::byte* vertex) const {
        ConvertedPoint point;
        point.position = position(vertex);
        if (layout_.color) {
            for (int k = 0; k < 3; ++k) {
                point.rgb[k] =
                    colorWord(access_.value(vertex, (*layout_.color)[k]), colorScales_[k]);
            }
        }
        if (layout_.normal) {
            const auto& n = *layout_.normal;
            point.normal = {saturateToFloat(access_.value(vertex, n[0])),
                            saturateToFloat(access_.value(vertex, n[1])),
                            saturateToFloat(access_.value(vertex, n[2]))};
        }
        if (layout_.intensity) {
            point.intensity = intensityWord(access_.value(vertex, *layout_.intensity));
        }
        return point;
    }

    InputFile file_;
    std::uint64_t vertexCount_;
    std::uint64_t vertexOffset_;
    std::size_t stride_;
    PlyVertexLayout layout_;
    VertexAccess access_;
    std::array<PlyColorScale, 3> colorScales_{};
    std::uint64_t nextVertex_ = 0;
    std::vector<std::byte> block_;
};

std::unique_ptr<PointRecordSource> openPly(const std::filesystem::path& path) {
    InputFile file(path);
    const std::string text = readHeaderText(file);
    const PlyHeader header = parsePlyHeader(text);
    if (header.encoding == PlyEncoding::Ascii) {
        return nullptr;
    }
    // The elements before the vertices are skipped by their size, which lists make unknown.
    std::uint64_t offset = header.bodyOffset;
    for (const PlyElement& element : header.elements) {
        const std::optional<std::size_t> stride = element.fixedStride();
        if (!stride) {
            return nullptr;
        }
        if (element.name != "vertex") {
            // Past the end of the file (no overflow): the vertices are then missing.
            const std::uint64_t left = file.size() - std::min(offset, file.size());
            offset = *stride > 0 && element.count > left / *stride
                         ? file.size() + 1
                         : offset + element.count * *stride;
            continue;
        }
        if (element.count == 0) {
            throw Error("it holds no points (its PLY header declares 0 vertices)");
        }
        const std::uint64_t available = offset > file.size() ? 0 : (file.size() - offset) / *stride;
        if (element.count > available) {
            throw Error(
                fmt::format("the PLY body ends inside vertex {} of {} declared in the header (file "
                            "truncated, or the count is wrong)",
                            available + 1, element.count));
        }
        std::string name = path.string();
        return std::make_unique<PlyRecordSource>(std::move(file), std::move(name), header, element,
                                                 offset, *stride);
    }
    throw Error("the PLY file has no 'vertex' element");
}

}  // namespace

std::unique_ptr<PointRecordSource> openPlyRecordSource(const std::filesystem::path& path) {
    try {
        return openPly(path);
    } catch (const Error& error) {
        throwNamed(path.string(), error);
    }
}

}  // namespace subscan
