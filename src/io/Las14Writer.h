#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "io/LazWriter.h"
#include "io/PointRecordSource.h"

// LAS 1.4 files of point formats 6-8 from point records (io/PointRecordSource.h), as they are:
// the records' integer coordinates with their scale and offset, every attribute unchanged.
namespace subscan {

/// What a LAS 1.4 header sums up from its records.
struct Las14Summary {
    std::uint64_t points = 0;
    std::array<std::uint64_t, 15> pointsByReturn{};
    glm::ivec3 storedMin{std::numeric_limits<int>::max()};
    glm::ivec3 storedMax{std::numeric_limits<int>::min()};
    double gpsTimeMin = std::numeric_limits<double>::infinity();
    double gpsTimeMax = -std::numeric_limits<double>::infinity();

    /// Adds records of a format 6-8 layout of `length` bytes.
    void add(std::span<const std::byte> records, std::size_t length);
    void add(const Las14Summary& other);
};

/// The 375-byte public header block of a LAS 1.4 file of `source`'s format, scale and offset
/// holding the records `summary` sums up, named as written by `software`; the fields that the
/// file's layout decides (offsets, VLR counts) are left for the writer (see encodeLazPrefix).
std::vector<std::byte> las14Header(const PointRecordSourceInfo& source, const Las14Summary& summary,
                                   std::string_view software);

/// The VLRs that describe `source`'s records: its coordinate system's WKT and its extra bytes'
/// descriptors, where it has them.
std::vector<LasVlr> las14Vlrs(const PointRecordSourceInfo& source);

/// Writes `records` as an uncompressed LAS 1.4 file, atomically. Errors name the file.
void writeLas14(const std::filesystem::path& path, const PointRecordSourceInfo& source,
                std::span<const std::byte> records);

/// Writes `records` as a LAZ 1.4 file (chunks of 50,000 points, LASzip's default), atomically.
void writeLaz14(const std::filesystem::path& path, const PointRecordSourceInfo& source,
                std::span<const std::byte> records);

}  // namespace subscan
