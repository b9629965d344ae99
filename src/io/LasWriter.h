#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>

#include <glm/vec3.hpp>

#include "core/PointCloud.h"

namespace subscan {

/// LAS 1.2 holds a class code in 5 bits (the byte's upper 3 are flags).
inline constexpr std::uint8_t kLargestLegacyClass = 31;
/// ASPRS class 1, "unclassified": what a code LAS 1.2 cannot hold is written as.
inline constexpr std::uint8_t kUnclassified = 1;

/// The classification byte writeLas stores for `code`: the code itself up to 31 (flags clear),
/// else kUnclassified.
std::uint8_t lasClassification(std::uint8_t code);

/// How a LAS file stores coordinates, per axis: file coordinate = int32 * scale + offset.
struct LasScaling {
    glm::dvec3 scale{1.0};
    glm::dvec3 offset{0.0};
};

/// The scaling writeLas uses for points within `bounds` (file coordinates). Per axis, the offset
/// is a round number at or just below the minimum: the minimum rounded down to a multiple of the
/// largest power of ten not above the extent (at least 1). The scale is the finest power of ten,
/// down to 1e-9, for which every point's stored value fits an int32: LAS spends 32 bits on every
/// coordinate whatever the scale, so the finest one that fits adds the least rounding. 1e-9 is
/// below any scanner's precision, and at UTM magnitudes (5e6 m) a double cannot resolve finer
/// steps anyway. Throws subscan::Error when even a scale of 1e7 cannot hold the extent (beyond
/// kMaxCoordinate, so never for a cloud a reader made).
LasScaling chooseLasScaling(const Bounds& bounds);

/// Writes `cloud` as LAS 1.2, atomically (see writeFileAtomically): point format 2 (with 16-bit
/// RGB, each 8-bit channel times 257) when the cloud has colours, else 0. Coordinates use
/// chooseLasScaling on the file coordinates' bounds; intensity is rounded and clamped to
/// 0..65535 (0 without intensities); every point is return 1 of 1, its class code as
/// lasClassification() gives it (0, never classified, without classifications). The header
/// names subscan as system and software and holds the bounds of the stored coordinates. LAS 1.2
/// has no normals, alpha or faces; they are not written. Throws subscan::Error naming the file
/// when it cannot be written.
void writeLas(const std::filesystem::path& path, const PointCloud& cloud);

}  // namespace subscan
