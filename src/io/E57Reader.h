#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "core/PointCloud.h"
#include "io/ReadContext.h"

namespace subscan {

/// Reads an ASTM E57 1.0 file (E2807) held in memory: 1024-byte pages, each checked against its
/// CRC-32C; the XML section; every scan of /data3D, its pose applied, concatenated into one
/// cloud. Point fields: cartesianX/Y/Z, or sphericalRange/Azimuth/Elevation when a scan has no
/// cartesian ones (Float, ScaledInteger or Integer, bit-packed); intensity (as stored);
/// colorRed/Green/Blue mapped from colorLimits to 0..255; points whose invalid state is not 0
/// are dropped. Other fields are skipped. Throws subscan::Error.
PointCloud readE57(std::span<const std::byte> file, ReadContext& context);

/// CRC-32C (Castagnoli, reflected, polynomial 0x1EDC6F41), the checksum of every E57 page.
std::uint32_t crc32c(std::span<const std::byte> bytes);

}  // namespace subscan
