#include "io/E57Reader.h"

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <glm/mat3x3.hpp>
#include <pugixml.hpp>

#include "core/Error.h"
#include "io/ByteOrder.h"

namespace subscan {

namespace {

// ASTM E2807 section 7: the file is a sequence of pages; each holds 1020 bytes of data followed
// by the CRC-32C of those bytes. Offsets in the file are "physical" (counting the checksums) or
// "logical" (counting data bytes only), as the standard says for each field.
constexpr std::uint64_t kPageSize = 1024;
constexpr std::uint64_t kPageDataSize = 1020;

constexpr std::string_view kSignature = "ASTM-E57";
constexpr std::uint64_t kFileHeaderSize = 48;

/// Byte offsets of the file header fields (E2807 table 8), all little-endian.
namespace header_field {
constexpr std::size_t kVersionMajor = 8;
constexpr std::size_t kVersionMinor = 12;
constexpr std::size_t kPhysicalLength = 16;
constexpr std::size_t kXmlPhysicalOffset = 24;
constexpr std::size_t kXmlLogicalLength = 32;
constexpr std::size_t kPageSize = 40;
}  // namespace header_field

/// A compressed vector's binary section starts with this header (E2807 table 19).
constexpr std::uint64_t kSectionHeaderSize = 32;
constexpr std::uint8_t kCompressedVectorSectionId = 1;

enum class PacketType : std::uint8_t { Index = 0, Data = 1, Empty = 2 };
/// Type, flags/reserved byte and the 16-bit "logical length - 1" open every packet.
constexpr std::size_t kPacketPrefixSize = 4;
/// A data packet adds its bytestream count, then one 16-bit buffer length per bytestream.
constexpr std::size_t kDataPacketHeaderSize = 6;

/// Writers pad the end of a bytestream to their register word, at most 64 bits; more unused
/// bits than that means the stream holds data the record count leaves unexplained.
constexpr std::uint64_t kMaxPaddingBits = 64;

/// Prototypes are flat in practice; the limit keeps a hostile file from recursing deep.
constexpr int kMaxPrototypeDepth = 32;

/// Colour of points whose isColorInvalid is set: the renderer's neutral grey for uncoloured
/// clouds, so they read as "no colour" rather than black.
constexpr std::uint8_t kNoColor = 200;

constexpr std::array<std::uint32_t, 256> makeCrc32cTable() {
    constexpr std::uint32_t kReflectedPolynomial = 0x82F63B78u;  // 0x1EDC6F41 bit-reversed
    std::array<std::uint32_t, 256> table{};
    for (std::uint32_t i = 0; i < 256; ++i) {
        std::uint32_t crc = i;
        for (int bit = 0; bit < 8; ++bit) {
            crc = (crc & 1u) != 0 ? (crc >> 1) ^ kReflectedPolynomial : crc >> 1;
        }
        table[i] = crc;
    }
    return table;
}

constexpr std::array<std::uint32_t, 256> kCrc32cTable = makeCrc32cTable();

std::uint64_t physicalFromLogical(std::uint64_t logical) {
    return logical / kPageDataSize * kPageSize + logical % kPageDataSize;
}

/// The file as E57 sees it: logical bytes stored in checksummed pages. Every page is checked
/// once, the first time any of its bytes is read, so nothing unchecked reaches a decoder.
class PagedFile {
  public:
    /// `file` holds exactly the header's physical length, a whole number of pages.
    explicit PagedFile(std::span<const std::byte> file)
        : file_(file), checked_(file.size() / kPageSize, false) {}

    std::uint64_t logicalLength() const { return checked_.size() * kPageDataSize; }
    std::uint64_t physicalLength() const { return file_.size(); }

    /// The logical offset of a physical one; nullopt when it lies in a checksum or past the end.
    std::optional<std::uint64_t> toLogical(std::uint64_t physical) const {
        if (physical >= file_.size() || physical % kPageSize >= kPageDataSize) {
            return std::nullopt;
        }
        return physical / kPageSize * kPageDataSize + physical % kPageSize;
    }

    /// Copies out.size() logical bytes starting at `offset`; the caller has checked that they
    /// lie inside logicalLength().
    void read(std::uint64_t offset, std::span<std::byte> out) {
        std::size_t done = 0;
        while (done < out.size()) {
            const std::uint64_t page = offset / kPageDataSize;
            const std::uint64_t within = offset % kPageDataSize;
            const std::size_t take = static_cast<std::size_t>(
                std::min<std::uint64_t>(out.size() - done, kPageDataSize - within));
            checkPage(page);
            std::memcpy(out.data() + done, file_.data() + page * kPageSize + within, take);
            done += take;
            offset += take;
        }
    }

    std::vector<std::byte> read(std::uint64_t offset, std::uint64_t length) {
        std::vector<std::byte> bytes(static_cast<std::size_t>(length));
        read(offset, bytes);
        return bytes;
    }

  private:
    void checkPage(std::uint64_t page) {
        if (checked_[page]) {
            return;
        }
        const std::byte* start = file_.data() + page * kPageSize;
        // The standard's reference implementation stores the checksum big-endian; both real
        // test files (libE57Format's bunnyDouble/bunnyInt32) agree on every page.
        const std::uint32_t stored = loadBigEndian<std::uint32_t>(start + kPageDataSize);
        const std::uint32_t computed = crc32c({start, kPageDataSize});
        if (stored != computed) {
            throw Error(fmt::format(
                "the E57 page at byte offset {} is corrupt: its stored CRC-32C is 0x{:08x}, but "
                "its data gives 0x{:08x}",
                page * kPageSize, stored, computed));
        }
        checked_[page] = true;
    }

    std::span<const std::byte> file_;
    std::vector<bool> checked_;
};

struct FileHeader {
    std::uint32_t versionMajor = 0;
    std::uint32_t versionMinor = 0;
    std::uint64_t physicalLength = 0;
    std::uint64_t xmlPhysicalOffset = 0;
    std::uint64_t xmlLogicalLength = 0;
};

/// Validates the file header against the file; what it returns describes bytes inside the file.
FileHeader parseFileHeader(std::span<const std::byte> file, ReadContext& context) {
    if (file.size() < kSignature.size() ||
        std::memcmp(file.data(), kSignature.data(), kSignature.size()) != 0) {
        throw Error("it does not start with the E57 signature 'ASTM-E57'");
    }
    if (file.size() < kFileHeaderSize) {
        throw Error(
            fmt::format("the file has only {} bytes, fewer than the {}-byte E57 file header (file "
                        "truncated?)",
                        file.size(), kFileHeaderSize));
    }
    auto field = [&](std::size_t offset) { return loadLittleEndian<std::uint64_t>(&file[offset]); };
    FileHeader header;
    header.versionMajor = loadLittleEndian<std::uint32_t>(&file[header_field::kVersionMajor]);
    header.versionMinor = loadLittleEndian<std::uint32_t>(&file[header_field::kVersionMinor]);
    header.physicalLength = field(header_field::kPhysicalLength);
    header.xmlPhysicalOffset = field(header_field::kXmlPhysicalOffset);
    header.xmlLogicalLength = field(header_field::kXmlLogicalLength);
    const std::uint64_t pageSize = field(header_field::kPageSize);
    if (header.versionMajor != 1) {
        throw Error(fmt::format("E57 version {}.{} is not supported (only version 1.x is)",
                                header.versionMajor, header.versionMinor));
    }
    if (pageSize != kPageSize) {
        throw Error(fmt::format(
            "the E57 header gives a page size of {} bytes, but E57 1.0 pages have {} bytes",
            pageSize, kPageSize));
    }
    if (header.physicalLength == 0 || header.physicalLength % kPageSize != 0) {
        throw Error(fmt::format(
            "the E57 header gives a file length of {} bytes, which is not a whole number of "
            "{}-byte pages",
            header.physicalLength, kPageSize));
    }
    if (file.size() < header.physicalLength) {
        throw Error(fmt::format(
            "the file has only {} of the {} bytes its E57 header gives (file truncated?)",
            file.size(), header.physicalLength));
    }
    if (file.size() > header.physicalLength) {
        context.warnings.push_back(fmt::format(
            "the file has {} bytes after the {} bytes its E57 header gives; they were ignored",
            file.size() - header.physicalLength, header.physicalLength));
    }
    const std::uint64_t pages = header.physicalLength / kPageSize;
    const std::uint64_t xmlPage = header.xmlPhysicalOffset / kPageSize;
    const std::uint64_t xmlWithin = header.xmlPhysicalOffset % kPageSize;
    // Compared in logical bytes, so no sum can wrap around however large the fields are.
    const std::uint64_t logicalLength = pages * kPageDataSize;
    if (xmlPage >= pages || xmlWithin >= kPageDataSize ||
        header.xmlLogicalLength > logicalLength - (xmlPage * kPageDataSize + xmlWithin)) {
        throw Error(fmt::format(
            "the E57 XML section ({} bytes at byte offset {}) lies outside the file's {} bytes "
            "of pages",
            header.xmlLogicalLength, header.xmlPhysicalOffset, header.physicalLength));
    }
    return header;
}

// ---------------------------------------------------------------------------------------------
// The XML section

std::string_view trimmed(std::string_view text) {
    const std::size_t first = text.find_first_not_of(" \t\r\n");
    if (first == std::string_view::npos) {
        return {};
    }
    return text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
}

/// Parses a whole number of type T (after trimming); errc tells "not a number" from "too large".
template <class T>
std::errc parseNumber(std::string_view text, T& value) {
    text = trimmed(text);
    if (text.starts_with('+')) {
        text.remove_prefix(1);  // C++ printf writes no '+', but XML writers may
    }
    const char* last = text.data() + text.size();
    const auto [end, ec] = std::from_chars(text.data(), last, value);
    if (ec == std::errc() && end != last) {
        return std::errc::invalid_argument;
    }
    return text.empty() ? std::errc::invalid_argument : ec;
}

/// What names a node in messages: "the field cartesianX of scan 1".
struct Where {
    std::string what;
};

[[noreturn]] void failNumber(const Where& where, std::string_view name, std::string_view text,
                             std::string_view kind) {
    throw Error(fmt::format("the E57 {} has {} '{}', which is not {}", where.what, name,
                            trimmed(text).substr(0, 40), kind));
}

std::int64_t integerAttribute(const pugi::xml_node& node, const char* name, std::int64_t fallback,
                              const Where& where) {
    const pugi::xml_attribute attribute = node.attribute(name);
    if (!attribute) {
        return fallback;
    }
    std::int64_t value = 0;
    const std::errc ec = parseNumber(attribute.value(), value);
    if (ec == std::errc::result_out_of_range) {
        // E57 integers are 64-bit: a wider bound would need bitstream values over 64 bits wide.
        throw Error(fmt::format(
            "the E57 {} has {} {}, beyond the 64-bit integers E57 allows, so its values would "
            "need more than 64 bits",
            where.what, name, trimmed(attribute.value()).substr(0, 40)));
    }
    if (ec != std::errc()) {
        failNumber(where, name, attribute.value(), "an integer");
    }
    return value;
}

std::uint64_t unsignedAttribute(const pugi::xml_node& node, const char* name, const Where& where) {
    const pugi::xml_attribute attribute = node.attribute(name);
    if (!attribute) {
        throw Error(fmt::format("the E57 {} has no {} attribute", where.what, name));
    }
    std::uint64_t value = 0;
    if (parseNumber(attribute.value(), value) != std::errc()) {
        failNumber(where, name, attribute.value(), "a non-negative 64-bit integer");
    }
    return value;
}

double doubleAttribute(const pugi::xml_node& node, const char* name, double fallback,
                       const Where& where) {
    const pugi::xml_attribute attribute = node.attribute(name);
    if (!attribute) {
        return fallback;
    }
    double value = 0.0;
    if (parseNumber(attribute.value(), value) != std::errc() || !std::isfinite(value)) {
        failNumber(where, name, attribute.value(), "a finite number");
    }
    return value;
}

/// The value of a numeric element (Integer, ScaledInteger or Float); E57 writes an empty
/// element for 0. `fallback` is used when the element is absent.
double elementValue(const pugi::xml_node& parent, const char* name, double fallback,
                    const Where& where) {
    const pugi::xml_node node = parent.child(name);
    if (!node) {
        return fallback;
    }
    const Where here{fmt::format("element {} of {}", name, where.what)};
    const std::string_view type = node.attribute("type").value();
    const std::string_view text = node.child_value();
    if (trimmed(text).empty()) {
        return 0.0;
    }
    if (type == "Integer" || type == "ScaledInteger") {
        std::int64_t raw = 0;
        if (parseNumber(text, raw) != std::errc()) {
            failNumber(here, "the value", text, "a 64-bit integer");
        }
        if (type == "Integer") {
            return static_cast<double>(raw);
        }
        return static_cast<double>(raw) * doubleAttribute(node, "scale", 1.0, here) +
               doubleAttribute(node, "offset", 0.0, here);
    }
    if (type != "Float") {
        throw Error(fmt::format("the E57 {} has type '{}' where a number is expected", here.what,
                                type.substr(0, 40)));
    }
    double value = 0.0;
    if (parseNumber(text, value) != std::errc() || !std::isfinite(value)) {
        failNumber(here, "the value", text, "a finite number");
    }
    return value;
}

enum class FieldType { Integer, ScaledInteger, Float32, Float64, Other };

/// How one prototype field is stored in its bytestream (E2807 8.4.5, bitPackCodec).
struct FieldCoding {
    std::string name;
    FieldType type = FieldType::Other;
    std::string typeName;  // as the XML writes it, for messages
    std::int64_t minimum = 0;
    std::int64_t maximum = 0;
    double scale = 1.0;
    double offset = 0.0;
    unsigned bits = 0;  // per value in the bytestream; 0 for a constant integer field
    std::optional<double> floatMinimum, floatMaximum;

    /// The smallest and largest value in file units (scale and offset applied).
    double lowest() const {
        return type == FieldType::ScaledInteger ? static_cast<double>(minimum) * scale + offset
               : type == FieldType::Integer     ? static_cast<double>(minimum)
                                                : floatMinimum.value_or(0.0);
    }
    double highest() const {
        return type == FieldType::ScaledInteger ? static_cast<double>(maximum) * scale + offset
               : type == FieldType::Integer     ? static_cast<double>(maximum)
                                                : floatMaximum.value_or(1.0);
    }
};

FieldCoding parseField(const pugi::xml_node& node, std::string name, int scanNumber) {
    FieldCoding field;
    field.name = std::move(name);
    field.typeName = node.attribute("type").value();
    const Where where{fmt::format("field {} of scan {}", field.name, scanNumber)};
    if (field.typeName == "Integer" || field.typeName == "ScaledInteger") {
        field.type = field.typeName == "Integer" ? FieldType::Integer : FieldType::ScaledInteger;
        // E2807 defaults: the full 64-bit range, scale 1, offset 0.
        field.minimum =
            integerAttribute(node, "minimum", std::numeric_limits<std::int64_t>::min(), where);
        field.maximum =
            integerAttribute(node, "maximum", std::numeric_limits<std::int64_t>::max(), where);
        if (field.maximum < field.minimum) {
            throw Error(fmt::format("the E57 {} has minimum {} greater than its maximum {}",
                                    where.what, field.minimum, field.maximum));
        }
        // Values are stored as value - minimum in ceil(log2(maximum - minimum + 1)) bits; the
        // difference of two int64 always fits in uint64, so this is at most 64.
        const std::uint64_t range =
            static_cast<std::uint64_t>(field.maximum) - static_cast<std::uint64_t>(field.minimum);
        field.bits = static_cast<unsigned>(std::bit_width(range));
        if (field.type == FieldType::ScaledInteger) {
            field.scale = doubleAttribute(node, "scale", 1.0, where);
            field.offset = doubleAttribute(node, "offset", 0.0, where);
            if (field.scale == 0.0) {
                throw Error(fmt::format("the E57 {} has scale 0", where.what));
            }
        }
    } else if (field.typeName == "Float") {
        const std::string_view precision = node.attribute("precision").value();
        if (precision.empty() || precision == "double") {
            field.type = FieldType::Float64;
            field.bits = 64;
        } else if (precision == "single") {
            field.type = FieldType::Float32;
            field.bits = 32;
        } else {
            throw Error(fmt::format("the E57 {} has precision '{}' (expected 'single' or 'double')",
                                    where.what, precision.substr(0, 40)));
        }
        if (node.attribute("minimum")) {
            field.floatMinimum = doubleAttribute(node, "minimum", 0.0, where);
        }
        if (node.attribute("maximum")) {
            field.floatMaximum = doubleAttribute(node, "maximum", 0.0, where);
        }
    } else if (field.typeName == "String") {
        field.type = FieldType::Other;  // its own bytestream, which we skip
    } else {
        throw Error(fmt::format("the E57 {} has the unknown type '{}'", where.what,
                                field.typeName.substr(0, 40)));
    }
    return field;
}

/// Every terminal element of a prototype is one bytestream, numbered in document order
/// (depth first); nested ones are named by their path.
void flattenPrototype(const pugi::xml_node& node, const std::string& prefix, int depth,
                      int scanNumber, std::vector<FieldCoding>& fields) {
    if (depth > kMaxPrototypeDepth) {
        throw Error(fmt::format("the E57 prototype of scan {} nests deeper than {} levels",
                                scanNumber, kMaxPrototypeDepth));
    }
    for (const pugi::xml_node& child : node.children()) {
        if (child.type() != pugi::node_element) {
            continue;
        }
        const std::string name = prefix + child.name();
        const std::string_view type = child.attribute("type").value();
        if (type == "Structure" || type == "Vector") {
            flattenPrototype(child, name + "/", depth + 1, scanNumber, fields);
        } else {
            fields.push_back(parseField(child, name, scanNumber));
        }
    }
}

/// What each point field of a scan means to us; the streams of other fields are skipped.
enum Role : std::size_t {
    kX,  // cartesianX, or sphericalRange
    kY,  // cartesianY, or sphericalAzimuth
    kZ,  // cartesianZ, or sphericalElevation
    kInvalidState,
    kIntensity,
    kIntensityInvalid,
    kRed,
    kGreen,
    kBlue,
    kColorInvalid,
    kRoleCount,
};

struct Pose {
    glm::dmat3 rotation{1.0};
    glm::dvec3 translation{0.0};
};

struct ScanLayout {
    int number = 0;  // 1-based, for messages
    std::uint64_t sectionPhysicalOffset = 0;
    std::uint64_t recordCount = 0;
    std::vector<FieldCoding> fields;                           // one per bytestream
    std::array<std::optional<std::size_t>, kRoleCount> roles;  // index into fields
    bool spherical = false;
    Pose pose;
    std::array<double, 3> colorMinimum{};
    std::array<double, 3> colorMaximum{};

    bool hasColor() const { return roles[kRed].has_value(); }
    bool hasIntensity() const { return roles[kIntensity].has_value(); }
};

std::optional<std::size_t> findField(const std::vector<FieldCoding>& fields,
                                     std::string_view name) {
    for (std::size_t i = 0; i < fields.size(); ++i) {
        if (fields[i].name == name) {
            return i;
        }
    }
    return std::nullopt;
}

/// Assigns roles X, Y, Z from the three named fields; false when none is present.
bool findCoordinates(ScanLayout& scan, const std::array<const char*, 3>& names,
                     std::string_view system) {
    int found = 0;
    for (int axis = 0; axis < 3; ++axis) {
        scan.roles[kX + axis] = findField(scan.fields, names[axis]);
        found += scan.roles[kX + axis].has_value();
    }
    if (found == 0) {
        return false;
    }
    for (int axis = 0; axis < 3; ++axis) {
        if (!scan.roles[kX + axis]) {
            throw Error(fmt::format("scan {} of the E57 file has {} coordinates but no {} field",
                                    scan.number, system, names[axis]));
        }
        const FieldCoding& field = scan.fields[*scan.roles[kX + axis]];
        if (field.type == FieldType::Other) {
            throw Error(fmt::format("the E57 field {} of scan {} has type {}, not a number",
                                    field.name, scan.number, field.typeName));
        }
    }
    return true;
}

/// The rotation of a unit quaternion (w, x, y, z) as a matrix (E2807 8.2.3: the pose maps the
/// scan's own coordinates into the file's).
glm::dmat3 rotationMatrix(double w, double x, double y, double z, int scanNumber) {
    const double norm = std::sqrt(w * w + x * x + y * y + z * z);
    if (!(norm > 0.0) || !std::isfinite(norm)) {
        throw Error(fmt::format(
            "the pose rotation of E57 scan {} (w x y z = {} {} {} {}) is not a rotation",
            scanNumber, w, x, y, z));
    }
    // Writers round the components; normalising keeps the rotation free of scaling.
    w /= norm;
    x /= norm;
    y /= norm;
    z /= norm;
    glm::dmat3 r;  // glm is column-major: r[column][row]
    r[0] = {1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)};
    r[1] = {2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x)};
    r[2] = {2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)};
    return r;
}

Pose parsePose(const pugi::xml_node& scanNode, int scanNumber) {
    Pose pose;
    const pugi::xml_node node = scanNode.child("pose");
    if (!node) {
        return pose;
    }
    if (const pugi::xml_node rotation = node.child("rotation")) {
        const Where where{fmt::format("pose rotation of scan {}", scanNumber)};
        pose.rotation = rotationMatrix(elementValue(rotation, "w", 1.0, where),
                                       elementValue(rotation, "x", 0.0, where),
                                       elementValue(rotation, "y", 0.0, where),
                                       elementValue(rotation, "z", 0.0, where), scanNumber);
    }
    if (const pugi::xml_node translation = node.child("translation")) {
        const Where where{fmt::format("pose translation of scan {}", scanNumber)};
        pose.translation = {elementValue(translation, "x", 0.0, where),
                            elementValue(translation, "y", 0.0, where),
                            elementValue(translation, "z", 0.0, where)};
    }
    return pose;
}

ScanLayout parseScan(const pugi::xml_node& node, int number, ReadContext& context) {
    ScanLayout scan;
    scan.number = number;
    const pugi::xml_node points = node.child("points");
    const Where where{fmt::format("compressed vector 'points' of scan {}", number)};
    if (!points || std::string_view(points.attribute("type").value()) != "CompressedVector") {
        throw Error(
            fmt::format("scan {} of the E57 file has no 'points' compressed vector", number));
    }
    scan.sectionPhysicalOffset = unsignedAttribute(points, "fileOffset", where);
    scan.recordCount = unsignedAttribute(points, "recordCount", where);
    const pugi::xml_node prototype = points.child("prototype");
    if (!prototype) {
        throw Error(fmt::format("the E57 points of scan {} have no prototype", number));
    }
    flattenPrototype(prototype, "", 0, number, scan.fields);

    if (!findCoordinates(scan, {"cartesianX", "cartesianY", "cartesianZ"}, "cartesian")) {
        scan.spherical = findCoordinates(
            scan, {"sphericalRange", "sphericalAzimuth", "sphericalElevation"}, "spherical");
        if (!scan.spherical) {
            throw Error(
                fmt::format("scan {} of the E57 file has neither cartesianX/Y/Z nor "
                            "sphericalRange/Azimuth/Elevation fields",
                            number));
        }
    }
    auto numeric = [&](std::string_view name) -> std::optional<std::size_t> {
        const auto index = findField(scan.fields, name);
        return index && scan.fields[*index].type != FieldType::Other ? index : std::nullopt;
    };
    scan.roles[kInvalidState] =
        numeric(scan.spherical ? "sphericalInvalidState" : "cartesianInvalidState");
    scan.roles[kIntensity] = numeric("intensity");
    if (scan.roles[kIntensity]) {
        scan.roles[kIntensityInvalid] = numeric("isIntensityInvalid");
    }

    const std::array<const char*, 3> colorNames{"colorRed", "colorGreen", "colorBlue"};
    const std::array<std::optional<std::size_t>, 3> colors{
        numeric(colorNames[0]), numeric(colorNames[1]), numeric(colorNames[2])};
    if (colors[0] && colors[1] && colors[2]) {
        const pugi::xml_node limits = node.child("colorLimits");
        const Where limitsWhere{fmt::format("colorLimits of scan {}", number)};
        for (int channel = 0; channel < 3; ++channel) {
            scan.roles[kRed + channel] = colors[channel];
            // Without colorLimits the field's own bounds are the limits (E2807 8.4.3).
            const FieldCoding& field = scan.fields[*colors[channel]];
            const std::string base = colorNames[channel];
            scan.colorMinimum[channel] =
                elementValue(limits, (base + "Minimum").c_str(), field.lowest(), limitsWhere);
            scan.colorMaximum[channel] =
                elementValue(limits, (base + "Maximum").c_str(), field.highest(), limitsWhere);
        }
        scan.roles[kColorInvalid] = numeric("isColorInvalid");
    } else if (colors[0] || colors[1] || colors[2]) {
        context.warnings.push_back(fmt::format(
            "scan {} of the E57 file has only some of colorRed, colorGreen and colorBlue; its "
            "colour was ignored",
            number));
    }
    scan.pose = parsePose(node, number);
    if (!context.sensor) {
        // A scan's own frame is centred on the scanner; its pose places it in the file's frame.
        context.sensor =
            SensorPose{scan.pose.translation, fmt::format("the origin of E57 scan {}{}", number,
                                                          node.child("pose") ? " (its pose)" : "")};
    }
    return scan;
}

std::vector<ScanLayout> parseXml(std::vector<std::byte>& xml, ReadContext& context) {
    pugi::xml_document document;
    const pugi::xml_parse_result parsed = document.load_buffer_inplace(
        xml.data(), xml.size(), pugi::parse_default, pugi::encoding_utf8);
    if (!parsed) {
        throw Error(fmt::format("the E57 XML section is not well-formed XML: {} at its byte {}",
                                parsed.description(), parsed.offset));
    }
    const pugi::xml_node root = document.child("e57Root");
    if (!root) {
        throw Error("the E57 XML section has no e57Root element");
    }
    const pugi::xml_node data3D = root.child("data3D");
    if (!data3D) {
        throw Error("the E57 XML section has no data3D element, so the file holds no 3D scans");
    }
    std::vector<ScanLayout> scans;
    for (const pugi::xml_node& child : data3D.children()) {
        if (child.type() == pugi::node_element) {
            scans.push_back(parseScan(child, static_cast<int>(scans.size()) + 1, context));
        }
    }
    if (scans.empty()) {
        throw Error("the E57 file's data3D vector is empty: it holds no 3D scans");
    }
    return scans;
}

// ---------------------------------------------------------------------------------------------
// The binary section of a compressed vector

/// Decodes one field's bytestream. The stream is the concatenation of this field's buffers in
/// all data packets, bit-packed least significant bit first: a value may start in one packet
/// and end in the next.
class FieldDecoder {
  public:
    FieldDecoder(const FieldCoding& coding, const ScanLayout& scan)
        : coding_(coding), scanNumber_(scan.number), recordCount_(scan.recordCount) {
        range_ =
            static_cast<std::uint64_t>(coding.maximum) - static_cast<std::uint64_t>(coding.minimum);
    }

    /// A field with no bits holds the same value in every record and needs no stream.
    bool constant() const { return coding_.bits == 0; }
    double constantValue() const { return convert(0); }

    void feed(std::span<const std::byte> bytes) {
        bitsFed_ += 8 * static_cast<std::uint64_t>(bytes.size());
        const unsigned bits = coding_.bits;
        if (bits == 0) {
            return;  // nothing to decode; checkComplete() refuses bytes a constant cannot have
        }
        std::size_t i = 0;
        if (bits % 8 == 0 && partialBits_ == 0) {
            // Whole-byte values (Float, 8/16/32/64-bit integers) straight from the buffer.
            const std::size_t width = bits / 8;
            while (i + width <= bytes.size() && decoded_ < recordCount_) {
                std::uint64_t raw = 0;
                for (std::size_t b = 0; b < width; ++b) {
                    raw |= std::to_integer<std::uint64_t>(bytes[i + b]) << (8 * b);
                }
                push(raw);
                i += width;
            }
        }
        for (; i < bytes.size(); ++i) {
            const unsigned byte = std::to_integer<unsigned>(bytes[i]);
            unsigned used = 0;
            while (used < 8 && decoded_ < recordCount_) {
                // partialBits_ < bits <= 64, so every shift here is below 64.
                const unsigned take = std::min(8 - used, bits - partialBits_);
                partial_ |= static_cast<std::uint64_t>((byte >> used) & ((1u << take) - 1u))
                            << partialBits_;
                partialBits_ += take;
                used += take;
                if (partialBits_ == bits) {
                    push(partial_);
                    partial_ = 0;
                    partialBits_ = 0;
                }
            }
        }
    }

    std::size_t available() const { return values_.size() - next_; }
    double take() { return constant() ? constantValue() : values_[next_++]; }
    void compact() {
        values_.erase(values_.begin(), values_.begin() + static_cast<std::ptrdiff_t>(next_));
        next_ = 0;
    }

    /// After the last packet: the stream must hold exactly the records, give or take padding.
    void checkComplete() const {
        const std::uint64_t needed = recordCount_ * coding_.bits;
        if (bitsFed_ < needed) {
            throw Error(fmt::format(
                "E57 scan {} declares {} records, but the bytestream of its field {} holds only "
                "{} (file truncated, or recordCount is wrong)",
                scanNumber_, recordCount_, coding_.name, bitsFed_ / coding_.bits));
        }
        if (bitsFed_ - needed >= kMaxPaddingBits) {
            throw Error(fmt::format(
                "E57 scan {} declares {} records, but the bytestream of its field {} holds {} "
                "bits more than they need (recordCount is wrong)",
                scanNumber_, recordCount_, coding_.name, bitsFed_ - needed));
        }
    }

  private:
    double convert(std::uint64_t raw) const {
        switch (coding_.type) {
            case FieldType::Float32:
                return std::bit_cast<float>(static_cast<std::uint32_t>(raw));
            case FieldType::Float64:
                return std::bit_cast<double>(raw);
            case FieldType::Integer:
            case FieldType::ScaledInteger:
            case FieldType::Other: {
                // raw <= maximum - minimum, so minimum + raw is in range; unsigned arithmetic
                // wraps where a signed sum of the same bits would overflow.
                const auto value = static_cast<double>(
                    static_cast<std::int64_t>(static_cast<std::uint64_t>(coding_.minimum) + raw));
                return coding_.type == FieldType::ScaledInteger
                           ? value * coding_.scale + coding_.offset
                           : value;
            }
        }
        return 0.0;
    }

    void push(std::uint64_t raw) {
        if ((coding_.type == FieldType::Integer || coding_.type == FieldType::ScaledInteger) &&
            raw > range_) {
            throw Error(fmt::format(
                "the E57 field {} of scan {} holds a value outside its minimum {} and maximum {} "
                "(record {}; corrupt data)",
                coding_.name, scanNumber_, coding_.minimum, coding_.maximum, decoded_));
        }
        values_.push_back(convert(raw));
        ++decoded_;
    }

    const FieldCoding& coding_;
    int scanNumber_;
    std::uint64_t recordCount_;
    std::uint64_t range_ = 0;
    std::uint64_t bitsFed_ = 0;
    std::uint64_t decoded_ = 0;
    std::uint64_t partial_ = 0;  // the low bits of a value whose rest is in the next buffer
    unsigned partialBits_ = 0;
    std::vector<double> values_;  // decoded, not yet taken
    std::size_t next_ = 0;
};

std::uint8_t toColorChannel(double value, double minimum, double maximum) {
    if (!(maximum > minimum)) {
        return 255;  // a one-value range: every point has the brightest (only) colour
    }
    const double scaled = (value - minimum) / (maximum - minimum) * 255.0;
    return static_cast<std::uint8_t>(std::clamp(std::round(scaled), 0.0, 255.0));
}

/// Whether toColorChannel loses bits of `value`: its limits span more than 8 bits (16-bit
/// colour, for one) and it is not one of the 256 values that an 8-bit channel gives back
/// (8-bit values times 257 in 0..65535).
bool colorNeedsMoreThanEightBits(double value, double minimum, double maximum) {
    const double span = maximum - minimum;
    if (!(span > 255.0)) {
        return false;
    }
    const double steps = (value - minimum) * 255.0;  // exact for integer fields
    return steps != std::round(steps / span) * span;
}

/// Where the decoded records go: positions through the pose, attributes, progress.
struct RecordSink {
    PointCloudBuilder& builder;
    const ReadContext& context;
    std::uint64_t totalRecords = 0;
    std::uint64_t done = 0;
    std::uint64_t invalid = 0;     // dropped for their invalid state
    bool colorCutTo8Bits = false;  // a kept point's colour needed more than 8 bits
};

void emitRecords(const ScanLayout& scan, std::vector<FieldDecoder>& decoders,
                 const std::array<std::optional<std::size_t>, kRoleCount>& decoderOf,
                 std::uint64_t count, RecordSink& sink) {
    auto value = [&](Role role, double fallback) {
        return decoderOf[role] ? decoders[*decoderOf[role]].take() : fallback;
    };
    PointRecord record;
    for (std::uint64_t i = 0; i < count; ++i) {
        // Every role is taken from its decoder for every record, kept or not, so the streams
        // stay in step.
        const glm::dvec3 stored{value(kX, 0.0), value(kY, 0.0), value(kZ, 0.0)};
        const double invalidState = value(kInvalidState, 0.0);
        const double intensity = value(kIntensity, 0.0);
        const double intensityInvalid = value(kIntensityInvalid, 0.0);
        const std::array<double, 3> color{value(kRed, 0.0), value(kGreen, 0.0), value(kBlue, 0.0)};
        const double colorInvalid = value(kColorInvalid, 0.0);
        // 1: direction only (no range), 2: no measurement; neither gives a position.
        if (invalidState != 0.0) {
            ++sink.invalid;
            continue;
        }
        glm::dvec3 local = stored;
        if (scan.spherical) {
            const double range = stored.x, azimuth = stored.y, elevation = stored.z;
            local = {range * std::cos(elevation) * std::cos(azimuth),
                     range * std::cos(elevation) * std::sin(azimuth), range * std::sin(elevation)};
        }
        record.position = scan.pose.rotation * local + scan.pose.translation;
        record.intensity = intensityInvalid != 0.0 ? 0.0f : saturateToFloat(intensity);
        if (colorInvalid != 0.0) {
            record.color = {kNoColor, kNoColor, kNoColor, 255};
        } else {
            record.color = {toColorChannel(color[0], scan.colorMinimum[0], scan.colorMaximum[0]),
                            toColorChannel(color[1], scan.colorMinimum[1], scan.colorMaximum[1]),
                            toColorChannel(color[2], scan.colorMinimum[2], scan.colorMaximum[2]),
                            255};
        }
        const std::size_t kept = sink.builder.validPoints();
        sink.builder.add(record);
        if (colorInvalid == 0.0 && sink.builder.validPoints() > kept) {
            for (int c = 0; c < 3; ++c) {
                sink.colorCutTo8Bits = sink.colorCutTo8Bits ||
                                       colorNeedsMoreThanEightBits(color[c], scan.colorMinimum[c],
                                                                   scan.colorMaximum[c]);
            }
        }
    }
    sink.done += count;
    sink.context.reportProgress(sink.done, sink.totalRecords);
}

/// The binary section of the scan's points, from its first data packet to its end, checked
/// against the file; `dataStart` is the section-relative offset of the first packet.
std::vector<std::byte> readSection(PagedFile& paged, const ScanLayout& scan,
                                   std::uint64_t& sectionLogical, std::uint64_t& dataStart) {
    const std::optional<std::uint64_t> start = paged.toLogical(scan.sectionPhysicalOffset);
    if (!start || paged.logicalLength() - *start < kSectionHeaderSize) {
        throw Error(fmt::format(
            "the E57 points of scan {} start at byte offset {}, outside the file's {} bytes of "
            "pages (or inside a page checksum)",
            scan.number, scan.sectionPhysicalOffset, paged.physicalLength()));
    }
    sectionLogical = *start;
    const std::vector<std::byte> header = paged.read(*start, kSectionHeaderSize);
    const auto sectionId = std::to_integer<std::uint8_t>(header[0]);
    if (sectionId != kCompressedVectorSectionId) {
        throw Error(fmt::format(
            "the E57 section at byte offset {} (the points of scan {}) has id {}, not the id {} "
            "of a compressed vector",
            scan.sectionPhysicalOffset, scan.number, sectionId, kCompressedVectorSectionId));
    }
    const auto length = loadLittleEndian<std::uint64_t>(&header[8]);
    const auto dataPhysical = loadLittleEndian<std::uint64_t>(&header[16]);
    if (length < kSectionHeaderSize || length > paged.logicalLength() - *start) {
        throw Error(fmt::format(
            "the E57 section at byte offset {} (the points of scan {}) claims {} bytes, more "
            "than the file holds after it (file truncated?)",
            scan.sectionPhysicalOffset, scan.number, length));
    }
    if (scan.recordCount == 0) {
        dataStart = length;
        return {};
    }
    const std::optional<std::uint64_t> data = paged.toLogical(dataPhysical);
    if (!data || *data < *start + kSectionHeaderSize || *data >= *start + length) {
        throw Error(fmt::format(
            "the E57 data of scan {} starts at byte offset {}, outside its section (byte offsets "
            "{} to {})",
            scan.number, dataPhysical, scan.sectionPhysicalOffset,
            physicalFromLogical(*start + length)));
    }
    dataStart = *data - *start;
    std::vector<std::byte> section(static_cast<std::size_t>(length));
    paged.read(*data, std::span(section).subspan(static_cast<std::size_t>(dataStart)));
    return section;
}

/// The bytestream buffers of one data packet (E2807 table 21), one per prototype field, checked
/// to lie inside the packet; `offset` is the packet's physical offset, for messages.
std::vector<std::span<const std::byte>> dataPacketBuffers(std::span<const std::byte> packet,
                                                          const ScanLayout& scan,
                                                          std::uint64_t offset) {
    if (packet.size() < kDataPacketHeaderSize) {
        throw Error(fmt::format(
            "the E57 data packet at byte offset {} is {} bytes long, too short for its header",
            offset, packet.size()));
    }
    const std::size_t streams = loadLittleEndian<std::uint16_t>(&packet[4]);
    if (streams != scan.fields.size()) {
        throw Error(fmt::format(
            "the E57 data packet at byte offset {} has {} bytestreams, but the prototype of scan "
            "{} has {} fields",
            offset, streams, scan.number, scan.fields.size()));
    }
    const std::size_t lengths = kDataPacketHeaderSize + 2 * streams;
    if (lengths > packet.size()) {
        throw Error(fmt::format(
            "the E57 data packet at byte offset {} is {} bytes long, too short for its {} "
            "bytestream lengths",
            offset, packet.size(), streams));
    }
    std::vector<std::span<const std::byte>> buffers;
    std::size_t position = lengths;
    for (std::size_t s = 0; s < streams; ++s) {
        const std::size_t bytes =
            loadLittleEndian<std::uint16_t>(&packet[kDataPacketHeaderSize + 2 * s]);
        if (bytes > packet.size() - position) {
            throw Error(fmt::format(
                "the E57 data packet at byte offset {} declares bytestreams longer than its {} "
                "bytes",
                offset, packet.size()));
        }
        buffers.push_back(packet.subspan(position, bytes));
        position += bytes;
    }
    return buffers;
}

void decodeScan(PagedFile& paged, const ScanLayout& scan, RecordSink& sink) {
    std::uint64_t sectionLogical = 0;
    std::uint64_t position = 0;
    const std::vector<std::byte> section = readSection(paged, scan, sectionLogical, position);
    // One bit per record is the least any stored field takes: more records than bits means the
    // count is wrong (a scan of constants only would be degenerate; it is refused as well).
    if (scan.recordCount > 8 * static_cast<std::uint64_t>(section.size())) {
        throw Error(
            fmt::format("E57 scan {} declares {} records, more than its {}-byte section can hold "
                        "(recordCount is wrong)",
                        scan.number, scan.recordCount, section.size()));
    }

    std::vector<FieldDecoder> decoders;
    std::vector<std::optional<std::size_t>> decoderOfStream(scan.fields.size());
    std::array<std::optional<std::size_t>, kRoleCount> decoderOf;
    for (std::size_t role = 0; role < kRoleCount; ++role) {
        if (const auto stream = scan.roles[role]) {
            if (!decoderOfStream[*stream]) {
                decoderOfStream[*stream] = decoders.size();
                decoders.emplace_back(scan.fields[*stream], scan);
            }
            decoderOf[role] = decoderOfStream[*stream];
        }
    }

    auto packetOffset = [&] { return physicalFromLogical(sectionLogical + position); };
    std::uint64_t emitted = 0;
    auto emitReady = [&] {
        std::uint64_t ready = scan.recordCount - emitted;
        for (const FieldDecoder& decoder : decoders) {
            if (!decoder.constant()) {
                ready = std::min<std::uint64_t>(ready, decoder.available());
            }
        }
        emitRecords(scan, decoders, decoderOf, ready, sink);
        emitted += ready;
        for (FieldDecoder& decoder : decoders) {
            decoder.compact();
        }
    };

    while (position < section.size()) {
        const std::byte* packet = section.data() + position;
        const std::uint64_t remaining = section.size() - position;
        if (remaining < kPacketPrefixSize) {
            throw Error(fmt::format(
                "the E57 section of scan {} ends inside the packet header at byte offset {}",
                scan.number, packetOffset()));
        }
        const auto type = std::to_integer<std::uint8_t>(packet[0]);
        const std::uint64_t length = loadLittleEndian<std::uint16_t>(packet + 2) + 1u;
        if (length > remaining) {
            throw Error(fmt::format(
                "the E57 packet at byte offset {} ({} bytes) runs past the end of the section of "
                "scan {}",
                packetOffset(), length, scan.number));
        }
        if (type == static_cast<std::uint8_t>(PacketType::Data)) {
            const auto buffers =
                dataPacketBuffers({packet, static_cast<std::size_t>(length)}, scan, packetOffset());
            for (std::size_t s = 0; s < buffers.size(); ++s) {
                if (decoderOfStream[s]) {
                    decoders[*decoderOfStream[s]].feed(buffers[s]);
                }
            }
            emitReady();
        } else if (type != static_cast<std::uint8_t>(PacketType::Index) &&
                   type != static_cast<std::uint8_t>(PacketType::Empty)) {
            // Index packets only speed up seeking, empty ones are filler: both are skipped.
            throw Error(fmt::format("the E57 packet at byte offset {} has the unknown type {}",
                                    packetOffset(), type));
        }
        position += length;
    }
    for (const FieldDecoder& decoder : decoders) {
        decoder.checkComplete();
    }
    emitReady();  // scans whose every field is constant have no data packets to trigger it
}

std::string describeScan(const ScanLayout& scan) {
    const FieldCoding& field = scan.fields[*scan.roles[kX]];
    std::string type = field.typeName;
    if (field.type == FieldType::Float32) {
        type = "Float (single)";
    } else if (field.type == FieldType::Float64) {
        type = "Float (double)";
    }
    return fmt::format("{} {}", scan.spherical ? "spherical" : "cartesian", type);
}

std::string describe(const FileHeader& header, const std::vector<ScanLayout>& scans) {
    std::vector<std::string> kinds;
    for (const ScanLayout& scan : scans) {
        std::string kind = describeScan(scan);
        if (std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) {
            kinds.push_back(std::move(kind));
        }
    }
    return fmt::format("E57 {}.{}, {} scan{}, {}", header.versionMajor, header.versionMinor,
                       scans.size(), scans.size() == 1 ? "" : "s", fmt::join(kinds, " + "));
}

/// An attribute is kept only when every scan has it: a cloud has it for all points or none.
bool everyScanHas(const std::vector<ScanLayout>& scans, bool (ScanLayout::*has)() const,
                  std::string_view attribute, ReadContext& context) {
    const auto with = std::count_if(scans.begin(), scans.end(),
                                    [&](const ScanLayout& scan) { return (scan.*has)(); });
    if (with > 0 && static_cast<std::size_t>(with) < scans.size()) {
        context.warnings.push_back(
            fmt::format("only {} of the {} E57 scans have {}; it was left out for all of them",
                        with, scans.size(), attribute));
    }
    return static_cast<std::size_t>(with) == scans.size();
}

}  // namespace

std::uint32_t crc32c(std::span<const std::byte> bytes) {
    std::uint32_t crc = 0xFFFFFFFFu;
    for (const std::byte byte : bytes) {
        crc = (crc >> 8) ^ kCrc32cTable[(crc ^ std::to_integer<std::uint32_t>(byte)) & 0xFFu];
    }
    return crc ^ 0xFFFFFFFFu;
}

PointCloud readE57(std::span<const std::byte> file, ReadContext& context) {
    const FileHeader header = parseFileHeader(file, context);
    PagedFile paged(file.first(static_cast<std::size_t>(header.physicalLength)));
    // The header lies in the first page: its checksum covers it too.
    paged.read(0, kFileHeaderSize);
    const std::optional<std::uint64_t> xmlStart = paged.toLogical(header.xmlPhysicalOffset);
    std::vector<std::byte> xml = paged.read(*xmlStart, header.xmlLogicalLength);
    const std::vector<ScanLayout> scans = parseXml(xml, context);
    context.formatDetail = describe(header, scans);

    std::uint64_t totalRecords = 0;
    for (const ScanLayout& scan : scans) {
        // Each count is checked before it is added, so the sum cannot wrap around.
        if (scan.recordCount > kMaxPoints || totalRecords + scan.recordCount > kMaxPoints) {
            throw Error(fmt::format(
                "the E57 scans declare more than the {} points subscan can hold", kMaxPoints));
        }
        totalRecords += scan.recordCount;
    }
    PointAttributes attributes;
    attributes.color = everyScanHas(scans, &ScanLayout::hasColor, "colour", context);
    attributes.intensity = everyScanHas(scans, &ScanLayout::hasIntensity, "intensity", context);
    // Never reserve beyond what the file could hold: a lying recordCount must not allocate.
    const std::uint64_t reserve = std::min<std::uint64_t>(totalRecords, file.size());
    PointCloudBuilder builder(attributes, static_cast<std::size_t>(reserve));
    if (context.keepFilePrecision) {
        builder.keepPositionResiduals();
    }
    RecordSink sink{builder, context, totalRecords};
    for (const ScanLayout& scan : scans) {
        decodeScan(paged, scan, sink);
    }
    if (sink.invalid > 0) {
        if (builder.validPoints() == 0 && builder.droppedPoints() == 0) {
            throw Error(fmt::format(
                "all {} points of the E57 file are marked invalid (no position measured)",
                sink.invalid));
        }
        context.warnings.push_back(
            fmt::format("skipped {} of {} E57 points marked invalid (cartesianInvalidState or "
                        "sphericalInvalidState not 0: no position measured)",
                        sink.invalid, totalRecords));
    }
    context.reportProgress(totalRecords, totalRecords);
    PointCloud cloud = builder.finish(context.warnings);
    // Positions are computed in double (scaled integers, spherical coordinates, each scan's
    // pose), so they are doubles whatever the fields' types; keeping them so is simplest.
    cloud.doubleCoordinates = true;
    cloud.colorCutTo8Bits = attributes.color && sink.colorCutTo8Bits;
    return cloud;
}

}  // namespace subscan
