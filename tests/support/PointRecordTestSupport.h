#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "io/PointRecordSource.h"

// What the tests of the point record sources share: reading a source to its end, and the fields
// of LAS 1.4 records of formats 6-8 decoded from R15 tables 15-17, restated here independently
// of the sources' own constants.
namespace subscan::test {

/// Every record of `source` from where it stands, read `piece` at a time.
inline std::vector<std::byte> readAllRecords(PointRecordSource& source, std::size_t piece) {
    std::vector<std::byte> records;
    while (source.read(records, piece) > 0) {
    }
    return records;
}

/// The records of `bytes` (`length` bytes each), sorted: two sets of records compare as
/// multisets, whatever order a writer put them in.
inline std::vector<std::string> sortedRecords(std::span<const std::byte> bytes,
                                              std::size_t length) {
    std::vector<std::string> records;
    for (std::size_t at = 0; at + length <= bytes.size(); at += length) {
        records.emplace_back(reinterpret_cast<const char*>(bytes.data() + at), length);
    }
    std::sort(records.begin(), records.end());
    return records;
}

/// The fields of one record of format 6, 7 or 8.
struct Las14Fields {
    std::array<std::int32_t, 3> xyz{};
    std::uint16_t intensity = 0;
    int returnNumber = 0;
    int numberOfReturns = 0;
    int classificationFlags = 0;  // synthetic 1, key-point 2, withheld 4, overlap 8
    int scannerChannel = 0;
    int scanDirection = 0;
    int edgeOfFlightLine = 0;
    int classification = 0;
    int userData = 0;
    std::int16_t scanAngle = 0;
    std::uint16_t pointSourceId = 0;
    double gpsTime = 0.0;
    std::array<std::uint16_t, 3> rgb{};
    std::uint16_t nir = 0;
    std::vector<std::byte> extraBytes;

    bool operator==(const Las14Fields&) const = default;
};

template <class T>
T loadRecordField(const std::byte* p) {
    T value;
    std::memcpy(&value, p, sizeof(T));
    return value;
}

inline Las14Fields decodeLas14(const std::byte* p, int pointFormat, std::size_t extraBytes) {
    Las14Fields f;
    for (int axis = 0; axis < 3; ++axis) {
        f.xyz[axis] = loadRecordField<std::int32_t>(p + 4 * axis);
    }
    f.intensity = loadRecordField<std::uint16_t>(p + 12);
    const auto returns = std::to_integer<int>(p[14]);
    f.returnNumber = returns & 15;
    f.numberOfReturns = returns >> 4;
    const auto flags = std::to_integer<int>(p[15]);
    f.classificationFlags = flags & 15;
    f.scannerChannel = (flags >> 4) & 3;
    f.scanDirection = (flags >> 6) & 1;
    f.edgeOfFlightLine = flags >> 7;
    f.classification = std::to_integer<int>(p[16]);
    f.userData = std::to_integer<int>(p[17]);
    f.scanAngle = loadRecordField<std::int16_t>(p + 18);
    f.pointSourceId = loadRecordField<std::uint16_t>(p + 20);
    f.gpsTime = loadRecordField<double>(p + 22);
    std::size_t end = 30;
    if (pointFormat >= 7) {
        for (int c = 0; c < 3; ++c) {
            f.rgb[c] = loadRecordField<std::uint16_t>(p + 30 + 2 * c);
        }
        end = 36;
    }
    if (pointFormat == 8) {
        f.nir = loadRecordField<std::uint16_t>(p + 36);
        end = 38;
    }
    f.extraBytes.assign(p + end, p + end + extraBytes);
    return f;
}

/// Record i of `records` in the source's format.
inline Las14Fields recordFields(const std::vector<std::byte>& records,
                                const PointRecordFormat& format, std::size_t i) {
    return decodeLas14(records.data() + i * format.recordLength(), format.pointFormat,
                       format.extraBytes);
}

}  // namespace subscan::test
