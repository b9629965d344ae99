#include "render/GpuPointCloud.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <span>

#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <glm/gtc/packing.hpp>
#include <glm/packing.hpp>

#include "core/Coloring.h"
#include "core/Error.h"
#include "core/LocalSpacing.h"
#include "shared/bindings.h"

namespace subscan {

namespace {

std::uint32_t pack(Rgba8 color) {
    return static_cast<std::uint32_t>(color.r) | static_cast<std::uint32_t>(color.g) << 8 |
           static_cast<std::uint32_t>(color.b) << 16 | static_cast<std::uint32_t>(color.a) << 24;
}

}  // namespace

std::uint32_t packNormal(const glm::vec3& normal) {
    const float l1 = std::abs(normal.x) + std::abs(normal.y) + std::abs(normal.z);
    if (!(l1 > 0.0f) || !std::isfinite(l1)) {
        return 0u;
    }
    glm::vec2 folded = glm::vec2(normal) / l1;
    if (normal.z < 0.0f) {
        const glm::vec2 sign(folded.x >= 0.0f ? 1.0f : -1.0f, folded.y >= 0.0f ? 1.0f : -1.0f);
        folded = (1.0f - glm::abs(glm::vec2(folded.y, folded.x))) * sign;
    }
    const std::uint32_t packed = glm::packSnorm2x16(folded);
    return packed == 0u ? 1u : packed;
}

glm::vec3 unpackNormal(std::uint32_t packed) {
    if (packed == 0u) {
        return glm::vec3(0.0f);
    }
    const glm::vec2 folded = glm::unpackSnorm2x16(packed);
    glm::vec3 normal(folded, 1.0f - std::abs(folded.x) - std::abs(folded.y));
    // The lower half was folded over the diagonals: unfold by the overshoot below z = 0.
    const float below = std::max(-normal.z, 0.0f);
    normal.x += normal.x >= 0.0f ? -below : below;
    normal.y += normal.y >= 0.0f ? -below : below;
    return glm::normalize(normal);
}

std::vector<std::uint32_t> displayColors(const PointCloud& cloud) {
    std::vector<std::uint32_t> packed(cloud.size());
    if (cloud.hasColors()) {
        std::transform(cloud.colors.begin(), cloud.colors.end(), packed.begin(), pack);
        return packed;
    }
    constexpr std::uint8_t kNeutral = 200;
    if (!cloud.hasIntensities()) {
        std::fill(packed.begin(), packed.end(), pack({kNeutral, kNeutral, kNeutral, 255}));
        return packed;
    }
    const std::vector<std::uint8_t> greys = intensityGreys(cloud);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        packed[i] = pack({greys[i], greys[i], greys[i], 255});
    }
    return packed;
}

GpuPointCloud::GpuPointCloud(const PointCloud& cloud, const GlCapabilities& capabilities,
                             std::size_t maxChunkPoints, PointMemory memory)
    : GpuPointCloud(GpuPointCloudUpload(cloud, {}, capabilities, maxChunkPoints, memory).take()) {}

GpuPointCloudUpload::GpuPointCloudUpload(const PointCloud& cloud, PackedPointAttributes packed,
                                         const GlCapabilities& capabilities,
                                         std::size_t maxChunkPoints, PointMemory memory)
    : packed_(std::move(packed)) {
    const std::size_t size = cloud.size();
    if (packed_.normals.empty() && cloud.hasNormals()) {
        packed_.normals = packNormals(cloud.normals);
    }
    const std::vector<glm::u16vec4>& spacing = packed_.localSpacing.halves;
    if (!spacing.empty() && spacing.size() != size) {
        throw Error(fmt::format("local spacing for {} points given to a cloud of {}",
                                spacing.size(), size));
    }
    if (!packed_.normals.empty() && packed_.normals.size() != size) {
        throw Error(
            fmt::format("{} normals given to a cloud of {} points", packed_.normals.size(), size));
    }
    cloud_.size_ = size;
    cloud_.origin_ = cloud.origin;
    cloud_.hasLocalSpacing_ = !spacing.empty();
    cloud_.sparseSpacingRatio_ =
        cloud_.hasLocalSpacing_ ? packed_.localSpacing.sparseSpacingRatio : 1.0f;
    cloud_.hasNormals_ = !packed_.normals.empty();

    // A chunk must fit one buffer texture (positions are the larger one: 3 texels a point) and
    // one dispatch.
    const std::size_t byTexture = capabilities.maxTextureBufferTexels / 3;
    const std::size_t byDispatch =
        static_cast<std::size_t>(capabilities.maxComputeWorkGroupsX) * SUBSCAN_POINTS_GROUP_SIZE;
    std::size_t chunkPoints = std::min({byTexture, byDispatch, std::size_t{1} << 26});
    if (maxChunkPoints > 0) {
        chunkPoints = std::min(chunkPoints, maxChunkPoints);
    }
    if (chunkPoints == 0) {
        throw Error("the OpenGL driver reports no room for buffer textures");
    }
    // The scan's own colours are uploaded as they are (an RGBA8 byte quadruple is the packed
    // uint32 on a little-endian machine): a copy of 40 MB for 10 M points saved.
    static_assert(std::endian::native == std::endian::little);
    const bool ownColors = cloud.hasColors();
    if (!ownColors) {
        converted_ = displayColors(cloud);
    }
    const auto* positions = reinterpret_cast<const std::byte*>(cloud.positions.data());
    const auto* colors = ownColors ? reinterpret_cast<const std::byte*>(cloud.colors.data())
                                   : reinterpret_cast<const std::byte*>(converted_.data());
    const auto* halves = reinterpret_cast<const std::byte*>(spacing.data());
    const auto* normals = reinterpret_cast<const std::byte*>(packed_.normals.data());
    // Borrowed where asked and the driver allows (the cloud's own arrays only: what this
    // object holds goes with it), else made and copied to by advance().
    const auto buffer = [&](std::size_t chunk, Buffer GpuPointCloud::Chunk::*member,
                            const std::byte* source, std::size_t bytes, bool mayBorrow,
                            const char* label) {
        if (mayBorrow && memory == PointMemory::Borrow) {
            if (Buffer inPlace = Buffer::borrowing(source, bytes, label)) {
                return inPlace;
            }
        }
        copies_.push_back({chunk, member, source, bytes, 0, label});
        return Buffer();
    };
    using Chunk = GpuPointCloud::Chunk;
    for (std::size_t first = 0; first < size; first += chunkPoints) {
        const std::size_t index = cloud_.chunks_.size();
        Chunk chunk;
        chunk.firstPoint = static_cast<std::uint32_t>(first);
        chunk.pointCount = static_cast<std::uint32_t>(std::min(chunkPoints, size - first));
        const std::size_t count = chunk.pointCount;
        chunk.positions = buffer(index, &Chunk::positions, positions + first * 3 * sizeof(float),
                                 count * 3 * sizeof(float), true, "points.positions");
        chunk.colors = buffer(index, &Chunk::colors, colors + first * sizeof(std::uint32_t),
                              count * sizeof(std::uint32_t), ownColors, "points.colors");
        if (cloud_.hasLocalSpacing_) {
            chunk.localSpacing =
                buffer(index, &Chunk::localSpacing, halves + first * sizeof(glm::u16vec4),
                       count * sizeof(glm::u16vec4), false, "points.localSpacing");
        }
        if (cloud_.hasNormals_) {
            chunk.normals = buffer(index, &Chunk::normals, normals + first * sizeof(std::uint32_t),
                                   count * sizeof(std::uint32_t), false, "points.normals");
        }
        cloud_.chunks_.push_back(std::move(chunk));
    }
}

bool GpuPointCloudUpload::advance(std::size_t bytes) {
    while (bytes > 0 && !finished()) {
        Copy& copy = copies_[next_];
        Buffer& target = cloud_.chunks_[copy.chunk].*copy.buffer;
        // Made with its first slice: making one costs about as much as filling it (llvmpipe
        // clears it: 290 ms for 280 MB), so the steps share that too.
        if (copy.copied == 0) {
            try {
                target = Buffer(copy.bytes, nullptr, copy.label);
            } catch (const Error& error) {
                throw Error(fmt::format("the GPU cannot hold the {} points ({:.0f} MB): {}",
                                        cloud_.size(), static_cast<double>(cloud_.bytes()) / 1e6,
                                        error.what()));
            }
        }
        const std::size_t slice = std::min(bytes, copy.bytes - copy.copied);
        target.upload(copy.copied, slice, copy.source + copy.copied);
        copy.copied += slice;
        bytes -= slice;
        if (copy.copied == copy.bytes) {
            ++next_;
        }
    }
    return finished();
}

std::size_t GpuPointCloudUpload::bytesLeft() const {
    std::size_t left = 0;
    for (std::size_t i = next_; i < copies_.size(); ++i) {
        left += copies_[i].bytes - copies_[i].copied;
    }
    return left;
}

GpuPointCloud GpuPointCloudUpload::take() && {
    advance(bytesLeft());
    return std::move(cloud_);
}

bool GpuPointCloud::borrowsPositions() const {
    return !chunks_.empty() && std::all_of(chunks_.begin(), chunks_.end(), [](const Chunk& chunk) {
        return chunk.positions.borrowed();
    });
}

void GpuPointCloud::setColors(const std::vector<Rgba8>& colors) {
    if (colors.size() != size_) {
        throw Error(fmt::format("{} colours given to a cloud of {} points", colors.size(), size_));
    }
    for (Chunk& chunk : chunks_) {
        chunk.colors = Buffer(chunk.pointCount * sizeof(std::uint32_t), &colors[chunk.firstPoint],
                              "points.colors");
    }
}

PackedLocalSpacing packLocalSpacing(const std::vector<glm::vec4>& spacing) {
    PackedLocalSpacing packed;
    packed.halves.resize(spacing.size());
    std::transform(spacing.begin(), spacing.end(), packed.halves.begin(),
                   [](const glm::vec4& entry) { return glm::u16vec4(glm::packHalf(entry)); });
    packed.sparseSpacingRatio = sparseSpacingRatio(spacing);
    return packed;
}

std::vector<std::uint32_t> packNormals(const std::vector<glm::vec3>& normals) {
    std::vector<std::uint32_t> packed(normals.size());
    std::transform(normals.begin(), normals.end(), packed.begin(), packNormal);
    return packed;
}

PackedPointAttributes packPointAttributes(const std::vector<glm::vec4>& spacing,
                                          const std::vector<glm::vec3>& normals) {
    return {packLocalSpacing(spacing), packNormals(normals)};
}

void GpuPointCloud::setLocalSpacing(const std::vector<glm::vec4>& spacing) {
    setLocalSpacing(packLocalSpacing(spacing));
}

void GpuPointCloud::setLocalSpacing(const PackedLocalSpacing& spacing) {
    if (spacing.halves.size() != size_) {
        throw Error(fmt::format("local spacing for {} points given to a cloud of {}",
                                spacing.halves.size(), size_));
    }
    for (Chunk& chunk : chunks_) {
        chunk.localSpacing = Buffer::fromSpan(
            std::span<const glm::u16vec4>(&spacing.halves[chunk.firstPoint], chunk.pointCount),
            "points.localSpacing");
    }
    hasLocalSpacing_ = true;
    sparseSpacingRatio_ = spacing.sparseSpacingRatio;
}

void GpuPointCloud::setNormals(const std::vector<glm::vec3>& normals) {
    setNormals(packNormals(normals));
}

void GpuPointCloud::setNormals(const std::vector<std::uint32_t>& packed) {
    if (packed.size() != size_) {
        throw Error(fmt::format("{} normals given to a cloud of {} points", packed.size(), size_));
    }
    for (Chunk& chunk : chunks_) {
        chunk.normals = Buffer::fromSpan(
            std::span<const std::uint32_t>(&packed[chunk.firstPoint], chunk.pointCount),
            "points.normals");
    }
    hasNormals_ = true;
}

}  // namespace subscan
