#pragma once

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

// LAS 1.4 point records of formats 6, 7 and 8 for the LAZ encoder's tests: random, but shaped
// like scans so that every coder path runs (see randomLas14Records), and a header for them.
namespace subscan::test {

/// A point format (6, 7 or 8) and a number of extra bytes: what the LAZ tests run over.
struct Las14Format {
    int pointFormat = 6;
    std::size_t extraBytes = 0;
};

/// How GoogleTest prints a Las14Format: "format 7 with 2 extra bytes".
void PrintTo(const Las14Format& format, std::ostream* out);
/// A test name: "Format7With2ExtraBytes".
std::string las14FormatName(const Las14Format& format);

/// The bytes of a record of `pointFormat` (6, 7 or 8) with `extraBytes` extra bytes.
std::size_t las14RecordLength(int pointFormat, std::size_t extraBytes);

struct Las14RecordOptions {
    int pointFormat = 6;
    std::size_t extraBytes = 0;
    /// Points of all four scanner channels, switching; false: channel 0 throughout.
    bool allChannels = true;
    std::uint32_t seed = 1;
};

/// `count` records in runs of 1 to 200 points, each run of one kind: every field changing
/// (returns, classification and its flags, scan angle, user data, point source, GPS time,
/// colour, NIR, extra bytes), only the coordinates changing (the other layers stay empty),
/// pulses of several returns sharing a GPS time, coordinates and values at their types' limits,
/// GPS times of interleaved flight lines with jumps beyond 32 bits, NaN and -0.0, and grey or
/// constant colours. Deterministic for a seed.
std::vector<std::byte> randomLas14Records(const Las14RecordOptions& options, std::size_t count);

/// A LAS 1.4 public header block (375 bytes) for `pointCount` records of `pointFormat` and
/// `recordLength` bytes: scale 0.001, offset (1000, 2000, 0), the WKT bit of the global
/// encoding set (as point formats 6-10 require), generating software "subscan tests".
std::vector<std::byte> las14Header(int pointFormat, std::size_t recordLength,
                                   std::uint64_t pointCount);

}  // namespace subscan::test
