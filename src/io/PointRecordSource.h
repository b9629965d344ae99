#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/PointCloud.h"

namespace subscan {

/// The one form every input takes on its way into a COPC file (`subscan index`) or a LAS-family
/// output (`subscan convert`): LAS 1.4 point records of format 6, 7 (RGB) or 8 (RGB + NIR),
/// each followed by the same extra bytes, with X, Y and Z as int32 on a grid of `scale` and
/// `offset` (file coordinate = stored * scale + offset).
struct PointRecordFormat {
    int pointFormat = 6;
    std::size_t extraBytes = 0;
    /// The payload of the LAS "extra bytes" VLR (user "LASF_Spec", record 4): one 192-byte
    /// descriptor per field, so the bytes keep their names (e.g. PDAL's NormalX, NormalY,
    /// NormalZ as floats). Empty when there are no extra bytes.
    std::vector<std::byte> extraBytesDescriptors;

    /// 30, 36 or 38 bytes (formats 6, 7, 8) plus the extra bytes.
    std::size_t recordLength() const;
    bool operator==(const PointRecordFormat&) const = default;
};

/// file coordinate = stored integer * scale + offset, per axis.
struct Quantization {
    glm::dvec3 scale{0.001};
    glm::dvec3 offset{0.0};
    bool operator==(const Quantization&) const = default;
};

/// What a source holds, known before its first record is read.
struct PointRecordSourceInfo {
    std::string name;              // the input's path (or synthetic:NAME), for messages
    std::uint64_t pointCount = 0;  // exact
    PointRecordFormat format;
    Quantization quantization;
    /// Bounds of the stored coordinates, in file coordinates: exact for inputs that are not
    /// LAS; for LAS and LAZ as the header declares them (which a writer may have left stale).
    glm::dvec3 min{0.0};
    glm::dvec3 max{0.0};
    std::string wkt;  // the coordinate reference system as OGC WKT; empty when unknown
    /// For a LAS source whose records have GPS times, its global encoding bit 0: whether they are
    /// Adjusted Standard GPS time (else GPS week seconds). nullopt where there are no GPS times
    /// (inputs that are not LAS, LAS point formats 0 and 2).
    std::optional<bool> standardGpsTime;
    /// The LAS header's file source ID (a flight line's number, say); 0, "none assigned", for
    /// inputs that are not LAS.
    std::uint16_t fileSourceId = 0;
    /// What was dropped or assumed on the way to records (wave packets, a coordinate system
    /// given only as GeoTIFF keys, colour filled in by a merge), one sentence each naming the
    /// input.
    std::vector<std::string> warnings;
};

/// Point records read in pieces, in file order. Out of core for LAS, LAZ, binary PLY and XYZ
/// text: memory holds one piece (and, for LAZ, the chunks being decoded), whatever the file's
/// size; other formats may load whole. Errors are subscan::Error sentences naming the file.
class PointRecordSource {
  public:
    virtual ~PointRecordSource() = default;
    virtual const PointRecordSourceInfo& info() const = 0;
    /// Appends at most `maxPoints` records to `records` and returns how many; 0 at the end.
    virtual std::size_t read(std::vector<std::byte>& records, std::size_t maxPoints) = 0;
    /// Starts again at the first record (an indexer reads its inputs more than once).
    virtual void rewind() = 0;
};

/// Opens any scan subscan reads (a file, or synthetic:NAME) as records. `threads` bounds the
/// decoding threads (LAZ chunks); 0 uses every core. An input without points is an error.
std::unique_ptr<PointRecordSource> openPointRecordSource(const std::filesystem::path& path,
                                                         unsigned threads = 0);

/// A cloud in memory as records (quantized as `convert` quantizes clouds), named `name` in
/// sentences: what `eval --point-budget` indexes.
std::unique_ptr<PointRecordSource> cloudRecordSource(PointCloud cloud, const std::string& name);

/// Several inputs as one source: one record format (the widest any input needs: format 7 when
/// one has colour, 8 when one has NIR; extra bytes must be the same fields in all) and one
/// quantization. Inputs that are not LAS have no grid of their own: they share the finest that
/// holds them all (a warning names one whose decimals it does not keep). LAS inputs keep their
/// stored integers exactly (same scales, offsets a whole number of steps apart), and so must
/// the shared grid of the others where both are merged. Inputs that cannot share them are one
/// error sentence naming both files and the field. The WKT must agree where both inputs have one,
/// and so must the kind of GPS time (standard or week seconds) where both have GPS times. The file
/// source ID is the inputs' where they all have the same, else 0 (the records keep their own point
/// source IDs).
std::unique_ptr<PointRecordSource> mergePointRecordSources(
    std::vector<std::unique_ptr<PointRecordSource>> sources);

}  // namespace subscan
