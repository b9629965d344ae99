#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace subscan {

/// 8-bit sRGB-encoded colour as scanners store it; alpha is 255 unless the file says otherwise.
struct Rgba8 {
    std::uint8_t r = 0, g = 0, b = 0, a = 255;
    friend bool operator==(const Rgba8&, const Rgba8&) = default;
};
static_assert(sizeof(Rgba8) == 4, "uploaded to the GPU as one uint32 per point");

using Triangle = std::array<std::uint32_t, 3>;

/// Points are addressed by 32-bit indices on the GPU; one value is reserved as "no point".
inline constexpr std::uint64_t kMaxPoints = 0xFFFFFFFEu;
inline constexpr std::uint32_t kInvalidIndex = 0xFFFFFFFFu;
/// Coordinates beyond this are corrupt data (the Earth is 1.3e7 m across); they are dropped.
inline constexpr double kMaxCoordinate = 1e15;

/// Axis-aligned box in the file's own coordinates (double: UTM and ECEF coordinates need it).
struct Bounds {
    glm::dvec3 min{std::numeric_limits<double>::infinity()};
    glm::dvec3 max{-std::numeric_limits<double>::infinity()};

    bool empty() const { return !(min.x <= max.x); }
    glm::dvec3 center() const { return 0.5 * (min + max); }
    glm::dvec3 extent() const { return max - min; }
    /// Corner 0..7: bit 0 picks max.x over min.x, bit 1 max.y, bit 2 max.z.
    glm::dvec3 corner(int i) const {
        return {(i & 1) ? max.x : min.x, (i & 2) ? max.y : min.y, (i & 4) ? max.z : min.z};
    }
    void add(const glm::dvec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
};

/// A point cloud in memory, one array per attribute (structure of arrays).
///
/// Positions are floats relative to `origin`, a double offset near the centre of the cloud, so
/// a scan in UTM coordinates keeps millimetre precision: file coordinate = origin + position
/// (+ positionResiduals, where kept). Optional attributes are either empty or exactly one entry
/// per point.
struct PointCloud {
    glm::dvec3 origin{0.0};
    std::vector<glm::vec3> positions;
    /// What the float positions lost of the file's coordinates, per point: file coordinate =
    /// origin + position + residual (each in double). Kept only where a load asked for the file's
    /// precision (`convert`, see keepResidualsWhereNeeded) and the floats round by more than
    /// positionTolerance; else empty. The renderer never reads it.
    std::vector<glm::vec3> positionResiduals;
    std::vector<Rgba8> colors;                  // sRGB-encoded
    std::vector<glm::vec3> normals;             // unit length where the file had them
    std::vector<float> intensities;             // as stored in the file (no normalisation)
    std::vector<std::uint8_t> classifications;  // ASPRS LAS class codes (LAS files only)
    std::vector<Triangle> triangles;            // vertex indices; ground-truth meshes only
    Bounds bounds;                              // exact, in file coordinates
    /// The finest step of the grid the file stored coordinates on: a LAS file's scale, or 10^-d
    /// for text whose coordinates have at most d decimals; 0 where the file has no grid.
    double coordinateStep = 0.0;
    /// Whether the file stored coordinates as doubles (a PLY or PCD double property, E57): finer
    /// than floats hold, on no grid.
    bool doubleCoordinates = false;
    /// Whether the file's colour used more than 8 bits a channel (16-bit values other than 8-bit
    /// ones times 257, E57 values of wider limits that 8 bits do not give back, PLY colour over
    /// 255 and PCD colour over 65535 in 32-bit channels), which `colors` holds cut to 8.
    bool colorCutTo8Bits = false;

    std::size_t size() const { return positions.size(); }
    bool hasColors() const { return !colors.empty(); }
    bool hasNormals() const { return !normals.empty(); }
    bool hasIntensities() const { return !intensities.empty(); }
    bool hasClassifications() const { return !classifications.empty(); }
    bool hasPositionResiduals() const { return !positionResiduals.empty(); }
    glm::dvec3 fileCoordinates(std::size_t i) const {
        return hasPositionResiduals()
                   ? origin + (glm::dvec3(positions[i]) + glm::dvec3(positionResiduals[i]))
                   : origin + glm::dvec3(positions[i]);
    }
};

/// Where no grid of the file's own says how finely its coordinates are meant (no
/// coordinateStep), float coordinates are taken to be exact to this fraction of the extent: a
/// micrometre on a metre-sized object scan, whose float files are no finer.
inline constexpr double kFloatErrorFraction = 1e-6;
/// Doubles on no grid (PLY or PCD double properties, E57) are kept to this, in scene units: a
/// micrometre in metres, finer than scanners measure.
inline constexpr double kDoubleCoordinateTolerance = 1e-6;

/// How far a coordinate may move from the file's and still be the file's own: half a step of
/// its grid (coordinateStep: a LAS scale, a text's decimals), kDoubleCoordinateTolerance for
/// doubles on no grid, a millionth of the extent for floats.
double positionTolerance(const PointCloud& cloud);

/// Drops `cloud.positionResiduals` unless one exceeds positionTolerance(cloud): only clouds whose
/// float positions lose more than the file's own precision (a 200 km survey on a millimetre
/// grid) pay for them. Call once the reader has set coordinateStep and doubleCoordinates.
void keepResidualsWhereNeeded(PointCloud& cloud);

/// Whether the 16-bit colour value `value` is one 8 bits do not give back: not an 8-bit value
/// times 257, as LAS writers (subscan's too) store 8-bit colour in 16 bits. The readers' test for
/// PointCloud::colorCutTo8Bits.
inline bool colorWordNeedsSixteenBits(double value) {
    return std::fmod(value, 257.0) != 0.0;
}

/// `value - rounded`, exactly, where `rounded` is `value` rounded to float: what the float lost.
/// The float is read back through a volatile: GCC 12.2 at -O2 (x86-64, no fast-math) was seen
/// to fold double(float(x)) back to x in a vectorised loop, which made this 0.
inline glm::dvec3 lostToFloat(const glm::dvec3& value, const glm::vec3& rounded) {
    glm::dvec3 lost;
    for (int axis = 0; axis < 3; ++axis) {
        const volatile float opaque = rounded[axis];
        lost[axis] = value[axis] - static_cast<double>(opaque);
    }
    return lost;
}

/// Which optional attributes a reader will provide for every point.
struct PointAttributes {
    bool color = false;
    bool normal = false;
    bool intensity = false;
    bool classification = false;
};

/// double -> float for attribute values from files: out-of-range values saturate (a plain cast
/// would be undefined behaviour); NaN stays NaN.
inline float saturateToFloat(double value) {
    constexpr double kLargest = std::numeric_limits<float>::max();
    return value > kLargest    ? std::numeric_limits<float>::infinity()
           : value < -kLargest ? -std::numeric_limits<float>::infinity()
                               : static_cast<float>(value);
}

/// The box to frame the cloud by: per axis from the 0.1 % to the 99.9 % quantile of the
/// coordinates (from a sample of at most 200,000 points), so that a few stray points far from
/// the object (common in scans) do not shrink it to a corner of the picture. A cloud of fewer
/// than 1,000 points keeps its exact bounds.
Bounds framingBounds(const PointCloud& cloud);

/// One decoded point as a reader produces it; attributes not announced to the builder are ignored.
struct PointRecord {
    glm::dvec3 position{0.0};
    Rgba8 color;
    glm::vec3 normal{0.0f};
    float intensity = 0.0f;
    std::uint8_t classification = 0;
};

/// Collects points from a reader: drops points with NaN, infinite or absurd (beyond
/// kMaxCoordinate) coordinates, counting them; tracks
/// exact double bounds and stores float positions relative to the first valid point; finish()
/// then re-centres them on the middle of the bounds.
class PointCloudBuilder {
  public:
    /// `mapVertexIndices`: the file has faces, so remember which file vertex became which point.
    PointCloudBuilder(PointAttributes attributes, std::size_t expectedPoints,
                      bool mapVertexIndices = false);

    void add(const PointRecord& point) {
        const glm::dvec3& p = point.position;
        // Also false for NaN; the bound keeps p - origin within float range.
        if (!(std::abs(p.x) <= kMaxCoordinate && std::abs(p.y) <= kMaxCoordinate &&
              std::abs(p.z) <= kMaxCoordinate)) {
            dropVertex();
            return;
        }
        if (cloud_.positions.empty()) {
            cloud_.origin = p;
        }
        if (mapVertexIndices_ && droppedPoints_ > 0) {
            vertexRemap_.push_back(static_cast<std::uint32_t>(cloud_.positions.size()));
        }
        cloud_.bounds.add(p);
        const glm::dvec3 relative = p - cloud_.origin;
        const glm::vec3 position(relative);
        cloud_.positions.push_back(position);
        if (keepResiduals_) {
            cloud_.positionResiduals.emplace_back(lostToFloat(relative, position));
        }
        if (attributes_.color) {
            cloud_.colors.push_back(point.color);
        }
        if (attributes_.normal) {
            cloud_.normals.push_back(point.normal);
        }
        if (attributes_.intensity) {
            cloud_.intensities.push_back(point.intensity);
        }
        if (attributes_.classification) {
            cloud_.classifications.push_back(point.classification);
        }
    }

    /// Triangles use the file's vertex numbering; finish() maps them past dropped vertices and
    /// drops triangles that touched one.
    void addTriangle(const Triangle& t) { cloud_.triangles.push_back(t); }

    /// Records, for every point, what its float position loses of the file's coordinate
    /// (PointCloud::positionResiduals). Call before the first add().
    void keepPositionResiduals() {
        keepResiduals_ = true;
        cloud_.positionResiduals.reserve(cloud_.positions.capacity());
    }

    std::size_t validPoints() const { return cloud_.positions.size(); }
    std::size_t droppedPoints() const { return droppedPoints_; }

    /// Throws subscan::Error when no valid point is left; warns (through `warnings`) about drops.
    PointCloud finish(std::vector<std::string>& warnings);

  private:
    void dropVertex();

    PointAttributes attributes_;
    bool mapVertexIndices_;
    bool keepResiduals_ = false;
    PointCloud cloud_;
    std::size_t droppedPoints_ = 0;
    // File vertex index -> kept index (kInvalidIndex when dropped); filled only for files with
    // faces and only once a drop happened, so clean files pay nothing.
    std::vector<std::uint32_t> vertexRemap_;
};

}  // namespace subscan
