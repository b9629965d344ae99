#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "core/Error.h"
#include "core/PointCloud.h"
#include "io/PointRecordSource.h"

// What the point record sources (src/io/*RecordSource.cpp) share: the layout of LAS 1.4 records,
// extra-bytes descriptors, and the conversion of points from inputs that are not LAS.
namespace subscan {

/// Byte offsets in LAS 1.4 point data record formats 6, 7 and 8 (R15, tables 15 to 17).
namespace las14 {
inline constexpr std::size_t kIntensity = 12;
inline constexpr std::size_t kReturns = 14;  // return number (bits 0-3), number of returns (4-7)
/// Classification flags (bits 0-3: synthetic, key-point, withheld, overlap), scanner channel
/// (4-5), scan direction (6), edge of flight line (7).
inline constexpr std::size_t kFlags = 15;
inline constexpr std::size_t kClassification = 16;
inline constexpr std::size_t kUserData = 17;
inline constexpr std::size_t kScanAngle = 18;  // int16, in 0.006 degree steps
inline constexpr std::size_t kPointSourceId = 20;
inline constexpr std::size_t kGpsTime = 22;
inline constexpr std::size_t kRgb = 30;  // formats 7 and 8
inline constexpr std::size_t kNir = 36;  // format 8
/// Return 1 of 1: what a point of a file without returns is.
inline constexpr std::uint8_t kFirstOfOneReturn = 0x11;

/// The record size of format 6, 7 or 8 before extra bytes: 30, 36 or 38.
std::size_t standardSize(int pointFormat);
}  // namespace las14

/// One descriptor of the LAS extra-bytes VLR (R15, table 24).
inline constexpr std::size_t kExtraBytesDescriptorSize = 192;

/// Appends the descriptor of a float32 field.
void appendFloatDescriptor(std::vector<std::byte>& descriptors, std::string_view name,
                           std::string_view description);
/// Descriptors of `bytes` bytes nobody has described: data type 0 ("undocumented extra bytes"),
/// whose options byte holds the size, so one descriptor per 255 bytes.
std::vector<std::byte> undocumentedDescriptors(std::size_t bytes);
/// How many bytes of each record the descriptors describe; nullopt when they are malformed (not
/// whole descriptors, an unknown data type, or undocumented bytes of size 0).
std::optional<std::size_t> describedBytes(std::span<const std::byte> descriptors);
/// Whether two descriptor lists describe the same fields: data type, name, size, and the scale
/// and offset where a descriptor has them (statistics, no-data values and descriptions may
/// differ).
bool sameExtraBytesFields(std::span<const std::byte> a, std::span<const std::byte> b);
/// The fields' names for messages, e.g. "NormalX, NormalY, NormalZ", or "none".
std::string extraBytesFieldNames(std::span<const std::byte> descriptors);

/// A point of an input that is not LAS, as records store it.
struct ConvertedPoint {
    glm::dvec3 position{0.0};  // file coordinates
    std::uint16_t intensity = 0;
    std::uint8_t classification = 0;  // ASPRS class; 0 is "never classified"
    std::array<std::uint16_t, 3> rgb{};
    glm::vec3 normal{0.0f};
};

/// Colour in LAS's 16-bit fields. 8-bit values are stored as value * 257, which maps 0..255 onto
/// 0..65535: LAS colour is 16-bit by the specification, writeLas stores 8-bit colour so, and
/// subscan's LAS reader (and any that divides by 257 or takes the high byte) gives the 8-bit
/// value back exactly. Values are rounded and clamped; NaN becomes 0.
std::uint16_t colorWordFromByte(double value);
std::uint16_t colorWordFromWord(double value);
std::uint16_t colorWordFromUnit(double value);  // 0..1
/// Intensity as writeLas stores it: rounded and clamped to 0..65535.
std::uint16_t intensityWord(double value);
/// Whether intensityWord keeps `value` as it is: a whole number within 0..65535.
bool fitsIntensityWord(double value);
/// Whether it keeps every one of a cloud's intensities.
bool fitIntensityWords(std::span<const float> intensities);
/// The warning for a source whose intensities do not all fit (a scanner's 0..1 confidence, a
/// Leica PTS file's -2048..2047): written rounded and clamped.
std::string intensitiesNotKept(const std::string& name);

/// Turns points of an input that is not LAS (PLY, text, a cloud loaded whole) into records of
/// format 6, or 7 with colour: return 1 of 1, the point's class, no flags, and the
/// normal as PDAL names it (float extra bytes NormalX, NormalY, NormalZ). Positions are quantized
/// with chooseLasScaling for the input's bounds: the finest power-of-ten step that fits.
class ConvertedRecordWriter {
  public:
    ConvertedRecordWriter(bool color, bool normals, const Bounds& bounds);

    const PointRecordFormat& format() const { return format_; }
    const Quantization& quantization() const { return quantization_; }
    /// Quantizes on `quantization` from now on (a grid a merge chose), which must hold the
    /// bounds given to the constructor.
    void setQuantization(const Quantization& quantization) { quantization_ = quantization; }
    /// The bounds of the stored coordinates of points within `bounds`, in file coordinates.
    Bounds storedBounds(const Bounds& bounds) const;
    /// Appends the point's record; throws subscan::Error when it lies outside the bounds given
    /// to the constructor by more than the 32-bit integers can hold.
    void append(std::vector<std::byte>& records, const ConvertedPoint& point) const;

  private:
    std::array<std::int32_t, 3> stored(const glm::dvec3& position) const;

    PointRecordFormat format_;
    Quantization quantization_;
    bool normals_;
};

/// The source of an input that is not LAS: its points become records through a
/// ConvertedRecordWriter. Such an input has no grid of its own: it gets the finest its bounds
/// allow, or the one a merge chose for several such inputs (mergePointRecordSources).
class ConvertedRecordSource : public PointRecordSource {
  public:
    const PointRecordSourceInfo& info() const final { return info_; }
    /// The exact bounds of the input's coordinates, in file coordinates.
    const Bounds& bounds() const { return bounds_; }
    /// Puts the records on `quantization`, which must hold bounds(). A warning names the input
    /// where its step is coarser than the grid the input's coordinates were written on (a text's
    /// decimals) and than the one chosen for its own bounds: they are rounded to it.
    void useQuantization(const Quantization& quantization);

  protected:
    /// Call once the points are known (a first pass, or the cloud loaded): the records get the
    /// finest grid `bounds` allow. `coordinateStep` is as PointCloud's: the input's own grid, 0
    /// for none.
    void startRecords(std::string name, std::uint64_t pointCount, bool color, bool normals,
                      const Bounds& bounds, double coordinateStep,
                      std::vector<std::string> warnings);
    const ConvertedRecordWriter& writer() const { return *writer_; }

  private:
    void setQuantization(const Quantization& quantization);

    std::optional<ConvertedRecordWriter> writer_;
    PointRecordSourceInfo info_;
    Bounds bounds_;
    /// The step the input's coordinates keep on their own: that of the grid they were written
    /// on, or of the grid chosen for their bounds where that is coarser; 0 where the input has
    /// no grid (floats, doubles).
    double keptStep_ = 0.0;
};

/// The warning of a converted input whose faces point records cannot hold: they were dropped
/// without a word where LAZ, COPC and the octree took a mesh.
std::string facesNotKept(const std::string& name, std::uint64_t faces);

/// How an input's warning ends when its coordinate system is given only as GeoTIFF keys.
inline constexpr std::string_view kGeoKeysOnly =
    "its coordinate system is given only as GeoTIFF keys, which subscan does not translate into "
    "WKT; its records go on without one";

/// Throws subscan::Error with `name` before the message: "name: message".
[[noreturn]] void throwNamed(const std::string& name, const Error& error);

/// The per-format openers behind openPointRecordSource; errors name `path`.
std::unique_ptr<PointRecordSource> openLasRecordSource(const std::filesystem::path& path,
                                                       unsigned threads);
/// nullptr when the PLY file is not binary with vertices of fixed size after elements of fixed
/// size (then it is loaded whole).
std::unique_ptr<PointRecordSource> openPlyRecordSource(const std::filesystem::path& path);
std::unique_ptr<PointRecordSource> openTextRecordSource(const std::filesystem::path& path);
/// Any scan loadScan reads, loaded whole.
std::unique_ptr<PointRecordSource> openCloudRecordSource(const std::string& source);

}  // namespace subscan
