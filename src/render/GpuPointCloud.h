#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/ext/vector_uint4_sized.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/PointCloud.h"
#include "gpu/GlContext.h"
#include "gpu/GlObjects.h"

namespace subscan {

/// A cloud's local spacing (estimateLocalSpacing's, one entry per point) as the GPU reads it:
/// four half floats a point, and the ratio GpuPointCloud::sparseSpacingRatio reports.
struct PackedLocalSpacing {
    std::vector<glm::u16vec4> halves;  // empty: no local spacing
    float sparseSpacingRatio = 1.0f;
};
PackedLocalSpacing packLocalSpacing(const std::vector<glm::vec4>& spacing);
/// packNormal of each.
std::vector<std::uint32_t> packNormals(const std::vector<glm::vec3>& normals);

/// What a GpuPointCloud uploads of a cloud beside its positions and colours, packed as the GPU
/// reads it. Packing is a pass over every point that callers may do off the render thread: it
/// took most of the 21 to 29 ms that the frame a viewer's view of a million points arrived in
/// spent on them (llvmpipe, 2 cores).
struct PackedPointAttributes {
    PackedLocalSpacing localSpacing;
    std::vector<std::uint32_t> normals;  // packNormal's, one per point; empty: none given
};
/// `spacing`'s local spacing and `normals` (unit or 0, one per point, or empty) packed.
PackedPointAttributes packPointAttributes(const std::vector<glm::vec4>& spacing,
                                          const std::vector<glm::vec3>& normals);

/// Whether a GpuPointCloud copies the cloud's points or reads the caller's arrays in place.
enum class PointMemory {
    Copy,
    /// The caller keeps the cloud alive and unchanged while the GPU cloud lives: where the
    /// driver reads client memory (Buffer::borrowing), the positions and the scan's own
    /// colours are used where they are — no copy of them (135 ms and 160 MB for 10 M points on
    /// llvmpipe); elsewhere, and for colours made from intensities, they are copied.
    Borrow,
};

/// A point cloud on the GPU, split into chunks that each fit one buffer texture and one
/// dispatch: positions as 3 floats (cloud-relative), colours as packed sRGB RGBA8. The
/// rasterizer reads both as buffer textures (Buffer::bindTexels), the GL_POINTS baseline as
/// vertex attributes. A cloud may also carry each point's local spacing (estimateLocalSpacing)
/// as four half floats, and its normal (packNormal).
class GpuPointCloud {
  public:
    struct Chunk {
        std::uint32_t firstPoint = 0;
        std::uint32_t pointCount = 0;
        Buffer positions;
        Buffer colors;
        Buffer localSpacing;  // empty unless hasLocalSpacing()
        Buffer normals;       // empty unless hasNormals()
    };

    /// `maxChunkPoints` 0 = as large as the driver allows; tests pass small values to exercise
    /// chunking. Throws subscan::Error when the GPU cannot hold the cloud. Uploads everything
    /// at once (GpuPointCloudUpload: in steps).
    GpuPointCloud(const PointCloud& cloud, const GlCapabilities& capabilities,
                  std::size_t maxChunkPoints = 0, PointMemory memory = PointMemory::Copy);

    /// Replaces the points' colours (sRGB-encoded, one per point), e.g. for another colouring.
    void setColors(const std::vector<Rgba8>& colors);
    /// Uploads estimateLocalSpacing's result, one entry per point, packed here or beforehand.
    void setLocalSpacing(const std::vector<glm::vec4>& spacing);
    void setLocalSpacing(const PackedLocalSpacing& spacing);
    bool hasLocalSpacing() const { return hasLocalSpacing_; }
    /// The local spacing ratio (a point's spacing or its across-lines vector, in h) that all
    /// points but the sparsest 0.1 % stay within, 1 without local spacing: how far the fill
    /// may reach beyond the outermost points (MinDepthPyramidPass). Not the largest: object
    /// scans have a few points 6 times sparser than the rest (the Happy Buddha: 99.9 % within
    /// 3.7, the largest 21.6), whose reach widened the passes' region so much that frames
    /// took 5 % longer.
    float sparseSpacingRatio() const { return sparseSpacingRatio_; }
    /// Uploads one normal per point (unit length, or 0 where none is known); the constructor
    /// uploads the cloud's own. Packed here, or beforehand (packNormal's, one per point).
    void setNormals(const std::vector<glm::vec3>& normals);
    void setNormals(const std::vector<std::uint32_t>& packed);
    bool hasNormals() const { return hasNormals_; }
    /// True when the positions are read from the cloud's own memory (PointMemory::Borrow on a
    /// driver that allows it).
    bool borrowsPositions() const;

    const std::vector<Chunk>& chunks() const { return chunks_; }
    std::size_t size() const { return size_; }
    const glm::dvec3& origin() const { return origin_; }
    std::size_t bytes() const {
        return size_ * (3 * sizeof(float) + sizeof(std::uint32_t) +
                        (hasLocalSpacing_ ? kLocalSpacingBytes : 0) +
                        (hasNormals_ ? sizeof(std::uint32_t) : 0));
    }

  private:
    std::vector<Chunk> chunks_;
    std::size_t size_ = 0;
    glm::dvec3 origin_{0.0};
    bool hasLocalSpacing_ = false;
    float sparseSpacingRatio_ = 1.0f;
    bool hasNormals_ = false;
    static constexpr std::size_t kLocalSpacingBytes = 4 * sizeof(std::uint16_t);

    friend class GpuPointCloudUpload;
    GpuPointCloud() = default;
};

/// A GpuPointCloud filled a bounded number of bytes at a time. Borrowed buffers are made at
/// once (they read the cloud in place and copy nothing); advance() makes the others and copies
/// to them in slices. The viewer copies a streamed view's points so over several frames while the
/// nodes before them stay on screen: a GPU's budget of 10 M points is some 240 MB, which would hold
/// up one frame for tens of milliseconds. `cloud` stays alive and unchanged until take().
class GpuPointCloudUpload {
  public:
    /// The cloud as GpuPointCloud's constructor takes it, with `packed`'s local spacing and
    /// normals (none given: the cloud's own normals). Throws subscan::Error when `packed` has
    /// another number of entries; advance() and take() when the GPU cannot hold the points.
    GpuPointCloudUpload(const PointCloud& cloud, PackedPointAttributes packed,
                        const GlCapabilities& capabilities, std::size_t maxChunkPoints = 0,
                        PointMemory memory = PointMemory::Copy);

    /// Copies up to `bytes` more; true once everything is on the GPU.
    bool advance(std::size_t bytes);
    bool finished() const { return next_ == copies_.size(); }
    std::size_t size() const { return cloud_.size(); }
    std::size_t bytesLeft() const;
    /// The cloud, every byte copied (advanced here where some are left).
    GpuPointCloud take() &&;

  private:
    /// One buffer's contents still to copy from the cloud (or from packed_, converted_).
    struct Copy {
        std::size_t chunk = 0;
        Buffer GpuPointCloud::Chunk::*buffer = nullptr;
        const std::byte* source = nullptr;
        std::size_t bytes = 0;
        std::size_t copied = 0;  // the buffer is made with the first slice
        const char* label = "";
    };

    GpuPointCloud cloud_;
    // Sources of copies: their arrays stay where they are when this object moves.
    PackedPointAttributes packed_;
    std::vector<std::uint32_t> converted_;  // displayColors() where the cloud has no colours
    std::vector<Copy> copies_;
    std::size_t next_ = 0;  // copies_[next_] is the one under way
};

/// A unit normal as the GPU reads it (SUBSCAN_TEXELS_POINT_NORMALS): its octahedral map
/// (Cigolle et al. 2014) as two snorm16, about 0.005 degrees apart; 0 stands for "no normal"
/// (a zero or non-finite vector), so the one normal that maps to 0, +z, is moved by 1/32767.
std::uint32_t packNormal(const glm::vec3& normal);
/// The inverse of packNormal (for tests; the shaders have their own): 0 for none.
glm::vec3 unpackNormal(std::uint32_t packed);

/// The colour each point is drawn with: its own, else its intensity as grey (stretched between
/// the 1st and 99th percentile), else a neutral light grey. Packed sRGB RGBA8.
std::vector<std::uint32_t> displayColors(const PointCloud& cloud);

}  // namespace subscan
