#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "core/PointCloud.h"
#include "io/LasHeader.h"
#include "io/ReadContext.h"

namespace subscan {

/// Reads a LAS file (versions 1.0-1.4, point formats 0-10) held in memory, also compressed as
/// LAZ (point formats 0-3 and 6-8, see io/laz) or COPC: coordinates with scale and offset
/// applied in double, intensity, the classification (the 5-bit class code of formats 0-5, the
/// 8-bit one of formats 6-10, without the flags) and RGB where the point format has it (16-bit
/// reduced to 8-bit; files that store 8-bit values in the 16-bit fields are detected). Throws
/// subscan::Error.
PointCloud readLas(std::span<const std::byte> file, ReadContext& context);

/// A LAS file's point records exactly as an uncompressed file stores them (LAZ and COPC
/// decompressed), for the fields the cloud does not keep (returns, flags, GPS time).
struct LasRecords {
    int pointFormat = 0;
    std::size_t recordLength = 0;
    std::vector<std::byte> bytes;  // point count x record length

    std::size_t size() const { return recordLength == 0 ? 0 : bytes.size() / recordLength; }
};

LasRecords readLasRecords(std::span<const std::byte> file, ReadContext& context);

/// Points of some of a LAS file's records, as readLas makes them: `head` holds the file's header
/// and VLRs (where PDAL's normals lie among the extra bytes), `colorSample` the records that
/// decide whether the 16-bit colour fields hold 8-bit values (readLas: all of them; a COPC
/// file's nodes: its root's, so that every node decides alike). `context` receives progress.
PointCloud lasRecordsToCloud(std::span<const std::byte> head, const LasHeader& header,
                             std::span<const std::byte> records,
                             std::span<const std::byte> colorSample, const ReadContext& context,
                             std::vector<std::string>& warnings);

}  // namespace subscan
