#include "io/PlyReader.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/PlyHeader.h"
#include "io/TextParsing.h"

namespace subscan {

std::size_t plySizeOf(PlyType type) {
    switch (type) {
        case PlyType::Int8:
        case PlyType::UInt8:
            return 1;
        case PlyType::Int16:
        case PlyType::UInt16:
            return 2;
        case PlyType::Int32:
        case PlyType::UInt32:
        case PlyType::Float32:
            return 4;
        case PlyType::Float64:
            return 8;
    }
    return 0;
}

bool isPlyInteger(PlyType type) {
    return type != PlyType::Float32 && type != PlyType::Float64;
}

namespace {

/// Whether an ascii body's `value` is one that a property of `type` holds, as a binary file's
/// always is.
bool plyTypeHolds(PlyType type, double value) {
    const auto within = [&](double low, double high) {
        return value >= low && value <= high && value == std::floor(value);
    };
    switch (type) {
        case PlyType::Int8:
            return within(-128.0, 127.0);
        case PlyType::UInt8:
            return within(0.0, 255.0);
        case PlyType::Int16:
            return within(-32768.0, 32767.0);
        case PlyType::UInt16:
            return within(0.0, 65535.0);
        case PlyType::Int32:
            return within(-2147483648.0, 2147483647.0);
        case PlyType::UInt32:
            return within(0.0, 4294967295.0);
        case PlyType::Float32:
        case PlyType::Float64:
            return true;
    }
    return false;
}

std::optional<PlyType> parseType(std::string_view name) {
    static constexpr std::array<std::pair<std::string_view, PlyType>, 16> kNames{{
        {"char", PlyType::Int8},
        {"int8", PlyType::Int8},
        {"uchar", PlyType::UInt8},
        {"uint8", PlyType::UInt8},
        {"short", PlyType::Int16},
        {"int16", PlyType::Int16},
        {"ushort", PlyType::UInt16},
        {"uint16", PlyType::UInt16},
        {"int", PlyType::Int32},
        {"int32", PlyType::Int32},
        {"uint", PlyType::UInt32},
        {"uint32", PlyType::UInt32},
        {"float", PlyType::Float32},
        {"float32", PlyType::Float32},
        {"double", PlyType::Float64},
        {"float64", PlyType::Float64},
    }};
    for (const auto& [typeName, type] : kNames) {
        if (typeName == name) {
            return type;
        }
    }
    return std::nullopt;
}

}  // namespace

std::optional<std::size_t> PlyElement::fixedStride() const {
    std::size_t stride = 0;
    for (const PlyProperty& property : properties) {
        if (property.isList) {
            return std::nullopt;
        }
        stride += plySizeOf(property.type);
    }
    return stride;
}

PlyHeader parsePlyHeader(std::string_view file) {
    PlyHeader header;
    std::size_t position = 0;
    int lineNumber = 0;
    bool sawFormat = false;
    auto nextLine = [&]() -> std::optional<std::string_view> {
        if (position >= file.size()) {
            return std::nullopt;
        }
        std::size_t end = file.find('\n', position);
        if (end == std::string_view::npos) {
            return std::nullopt;  // the header must end with a newline after end_header
        }
        std::string_view line = file.substr(position, end - position);
        position = end + 1;
        ++lineNumber;
        if (!line.empty() && line.back() == '\r') {
            line.remove_suffix(1);
        }
        return line;
    };

    const auto magic = nextLine();
    if (!magic || *magic != "ply") {
        throw Error("it does not start with the PLY magic line 'ply'");
    }
    while (true) {
        const auto line = nextLine();
        if (!line) {
            throw Error("the PLY header has no 'end_header' line (file truncated?)");
        }
        const std::vector<std::string_view> words = splitWords(*line);
        if (words.empty()) {
            continue;
        }
        const std::string_view keyword = words[0];
        auto fail = [&](std::string_view what) {
            throw Error(fmt::format("PLY header line {} {} {}", lineNumber,
                                    quoteForMessage(*line, 60), what));
        };
        if (keyword == "end_header") {
            break;
        }
        // Stanford's range scans carry 'obj_info' and stray 'bye' lines; both say nothing
        // about the layout, like comments.
        if (keyword == "comment" || keyword == "obj_info" || keyword == "bye") {
            continue;
        }
        if (keyword == "format") {
            if (words.size() != 3) {
                fail("should read 'format <encoding> 1.0'");
            }
            if (words[1] == "ascii") {
                header.encoding = PlyEncoding::Ascii;
            } else if (words[1] == "binary_little_endian") {
                header.encoding = PlyEncoding::BinaryLittleEndian;
            } else if (words[1] == "binary_big_endian") {
                header.encoding = PlyEncoding::BinaryBigEndian;
            } else {
                fail(
                    "names an unknown encoding (expected ascii, binary_little_endian or "
                    "binary_big_endian)");
            }
            header.version = std::string(words[2]);
            sawFormat = true;
        } else if (keyword == "element") {
            if (words.size() != 3) {
                fail("should read 'element <name> <count>'");
            }
            PlyElement element;
            element.name = std::string(words[1]);
            const auto [end, ec] =
                std::from_chars(words[2].data(), words[2].data() + words[2].size(), element.count);
            if (ec != std::errc() || end != words[2].data() + words[2].size()) {
                fail("has an element count that is not a non-negative integer");
            }
            header.elements.push_back(std::move(element));
        } else if (keyword == "property") {
            if (header.elements.empty()) {
                fail("declares a property before any element");
            }
            PlyProperty property;
            if (words.size() >= 2 && words[1] == "list") {
                if (words.size() != 5) {
                    fail("should read 'property list <count type> <item type> <name>'");
                }
                const auto countType = parseType(words[2]);
                const auto itemType = parseType(words[3]);
                if (!countType || !itemType) {
                    fail("uses an unknown property type");
                }
                if (!isPlyInteger(*countType)) {
                    fail("has a list count type that is not an integer type");
                }
                property.isList = true;
                property.countType = *countType;
                property.type = *itemType;
                property.name = std::string(words[4]);
            } else {
                if (words.size() != 3) {
                    fail("should read 'property <type> <name>'");
                }
                const auto type = parseType(words[1]);
                if (!type) {
                    fail("uses an unknown property type");
                }
                property.type = *type;
                property.name = std::string(words[2]);
            }
            header.elements.back().properties.push_back(std::move(property));
        } else {
            fail("is not a PLY header keyword");
        }
    }
    if (!sawFormat) {
        throw Error("the PLY header has no 'format' line");
    }
    header.bodyOffset = position;
    header.headerLines = static_cast<std::size_t>(lineNumber);
    return header;
}

PlyVertexLayout findPlyVertexLayout(const PlyElement& vertex) {
    auto scalar = [&](std::string_view name) -> std::optional<std::size_t> {
        const auto index = vertex.find(name);
        if (index && vertex.properties[*index].isList) {
            throw Error(
                fmt::format("the PLY vertex property '{}' is declared as a list, but it "
                            "must be a single value",
                            name));
        }
        return index;
    };
    auto triple = [&](std::string_view a, std::string_view b,
                      std::string_view c) -> std::optional<std::array<std::size_t, 3>> {
        const auto ia = scalar(a), ib = scalar(b), ic = scalar(c);
        if (ia && ib && ic) {
            return std::array<std::size_t, 3>{*ia, *ib, *ic};
        }
        return std::nullopt;
    };

    PlyVertexLayout layout;
    for (int axis = 0; axis < 3; ++axis) {
        const std::string_view name = std::array{"x", "y", "z"}[axis];
        const auto index = scalar(name);
        if (!index) {
            throw Error(fmt::format("the PLY vertex element has no '{}' property", name));
        }
        layout.position[axis] = *index;
    }
    layout.color = triple("red", "green", "blue");
    layout.alpha = scalar("alpha");
    if (!layout.color) {
        layout.color = triple("diffuse_red", "diffuse_green", "diffuse_blue");
        layout.alpha = scalar("diffuse_alpha");
    }
    layout.normal = triple("nx", "ny", "nz");
    layout.intensity = scalar("intensity");
    if (!layout.intensity) {
        layout.intensity = scalar("scalar_intensity");
    }
    return layout;
}

bool isLargePlyColorValue(PlyType type, double value) {
    if (type == PlyType::UInt16 || type == PlyType::Int16) {
        return value > 255.0;
    }
    return !isPlyInteger(type) && value > 1.0;
}

PlyColorScale plyColorScale(PlyType type, bool largeValues) {
    if (type == PlyType::UInt16 || type == PlyType::Int16) {
        return largeValues ? PlyColorScale::Word : PlyColorScale::Byte;
    }
    if (!isPlyInteger(type)) {
        return largeValues ? PlyColorScale::Byte : PlyColorScale::Unit;
    }
    return PlyColorScale::Byte;
}

namespace {

std::uint8_t toColorChannel(double value, PlyColorScale scale) {
    double scaled = value;
    if (scale == PlyColorScale::Word) {
        scaled = value / 257.0;  // 65535 -> 255
    } else if (scale == PlyColorScale::Unit) {
        scaled = value * 255.0;
    }
    if (!(scaled > 0.0)) {
        return 0;  // also NaN
    }
    return static_cast<std::uint8_t>(std::min(255.0, scaled + 0.5));
}

constexpr std::string_view kFaceListNames[] = {"vertex_indices", "vertex_index"};

std::optional<std::size_t> findFaceList(const PlyElement& face) {
    for (std::string_view name : kFaceListNames) {
        if (const auto index = face.find(name); index && face.properties[*index].isList) {
            return index;
        }
    }
    return std::nullopt;
}

/// Decodes the body: binary (either byte order) and ascii share everything but value access.
/// An ascii item is one line (blank lines aside), so a line with the wrong number of values is
/// an error rather than a shift of every value after it.
class PlyBodyReader {
  public:
    PlyBodyReader(const PlyHeader& header, std::span<const std::byte> file, ReadContext& context)
        : header_(header), file_(file), context_(context), lineNumber_(header.headerLines) {}

    PointCloud read();

  private:
    // The decoded values of one item.
    struct ItemValues {
        std::vector<double> scalar;              // per property (scalars only)
        std::vector<std::uint32_t> faceIndices;  // the face list, when reading faces
    };

    bool binary() const { return header_.encoding != PlyEncoding::Ascii; }
    double loadBinary(PlyType type, const std::byte* p) const;
    void readItem(const PlyElement& element, std::uint64_t itemIndex,
                  std::optional<std::size_t> faceList, ItemValues& values);
    void readBinaryItem(const PlyElement& element, std::uint64_t itemIndex,
                        std::optional<std::size_t> faceList, ItemValues& values);
    void readAsciiItem(const PlyElement& element, std::uint64_t itemIndex,
                       std::optional<std::size_t> faceList, ItemValues& values);
    void skipElement(const PlyElement& element);
    [[noreturn]] void failTruncated(const PlyElement& element, std::uint64_t itemIndex) const;
    std::uint64_t listLength(double countValue, const PlyElement& element,
                             std::uint64_t itemIndex) const;
    bool nextAsciiLine();
    std::optional<double> nextAsciiValue(const PlyElement& element, std::uint64_t itemIndex);
    [[noreturn]] void failAsciiLine(const PlyElement& element, std::uint64_t itemIndex) const;
    void warnAboutAsciiLinesLeft();

    const PlyHeader& header_;
    std::span<const std::byte> file_;
    ReadContext& context_;
    std::size_t position_ = 0;
    // Ascii only: the line read last (its bytes, number, and whether a line end ends it), and
    // the next value's place on it.
    std::size_t lineStart_ = 0;
    std::size_t lineEnd_ = 0;
    std::size_t lineNumber_;
    bool lineEnded_ = false;
    std::size_t cursor_ = 0;
};

double PlyBodyReader::loadBinary(PlyType type, const std::byte* p) const {
    return loadPlyValue(type, header_.encoding == PlyEncoding::BinaryBigEndian, p);
}

void PlyBodyReader::failTruncated(const PlyElement& element, std::uint64_t itemIndex) const {
    throw Error(
        fmt::format("the PLY body ends inside {} {} of {} declared in the header (file "
                    "truncated, or the count is wrong)",
                    element.name, itemIndex + 1, element.count));
}

std::uint64_t PlyBodyReader::listLength(double countValue, const PlyElement& element,
                                        std::uint64_t itemIndex) const {
    // Lists longer than 2^32 entries cannot be real, and the bound keeps the cast defined.
    if (!(countValue >= 0.0 && countValue <= 4294967295.0 &&
          countValue == std::floor(countValue))) {
        throw Error(fmt::format("the PLY body has the invalid list length {} in {} {}{}",
                                countValue, element.name, itemIndex + 1,
                                binary() ? "" : fmt::format(" (line {})", lineNumber_)));
    }
    return static_cast<std::uint64_t>(countValue);
}

/// Moves to the next line that holds a value; false at the body's end.
bool PlyBodyReader::nextAsciiLine() {
    const std::string_view text(reinterpret_cast<const char*>(file_.data()), file_.size());
    while (position_ < text.size()) {
        lineStart_ = position_;
        lineEnd_ = std::min(text.find('\n', position_), text.size());
        lineEnded_ = lineEnd_ < text.size();
        position_ = std::min(lineEnd_ + 1, text.size());
        ++lineNumber_;
        cursor_ = lineStart_;
        while (cursor_ < lineEnd_ && isWhitespace(text[cursor_])) {
            ++cursor_;
        }
        if (cursor_ < lineEnd_) {
            return true;
        }
    }
    return false;
}

/// The current line's next value, or nullopt at its end.
std::optional<double> PlyBodyReader::nextAsciiValue(const PlyElement& element,
                                                    std::uint64_t itemIndex) {
    if (cursor_ == lineEnd_) {
        return std::nullopt;
    }
    const char* text = reinterpret_cast<const char*>(file_.data());
    double value = 0.0;
    const char* end = parseNumber(text + cursor_, text + lineEnd_, value);
    if (end == nullptr || (end < text + lineEnd_ && !isWhitespace(*end))) {
        std::size_t tokenEnd = cursor_;
        while (tokenEnd < lineEnd_ && !isWhitespace(text[tokenEnd])) {
            ++tokenEnd;
        }
        throw Error(fmt::format("the PLY body has the non-numeric value {} in {} {} (line {})",
                                quoteForMessage({text + cursor_, tokenEnd - cursor_}), element.name,
                                itemIndex + 1, lineNumber_));
    }
    cursor_ = static_cast<std::size_t>(end - text);
    while (cursor_ < lineEnd_ && isWhitespace(text[cursor_])) {
        ++cursor_;
    }
    return value;
}

/// The current line holds more or fewer values than its item needs: says how many it needs.
void PlyBodyReader::failAsciiLine(const PlyElement& element, std::uint64_t itemIndex) const {
    const std::string_view text(reinterpret_cast<const char*>(file_.data()), file_.size());
    const std::vector<std::string_view> words =
        splitWords(text.substr(lineStart_, lineEnd_ - lineStart_));
    // One value per scalar; a list's count, then that many. The line was read up to where it
    // fell short or went on, so the counts on it are valid list lengths.
    std::size_t needed = 0;
    bool countsKnown = true;
    for (const PlyProperty& property : element.properties) {
        ++needed;
        if (!property.isList) {
            continue;
        }
        if (needed > words.size()) {
            countsKnown = false;  // a list has its count at least
            continue;
        }
        const std::string_view countWord = words[needed - 1];
        double count = 0.0;
        parseNumber(countWord.data(), countWord.data() + countWord.size(), count);
        needed += static_cast<std::size_t>(count);
    }
    if (needed > words.size() && !lineEnded_) {
        failTruncated(element, itemIndex);  // the file ends inside this line
    }
    throw Error(fmt::format(
        "PLY line {} has {} values, but the header's properties of {} {} need {}{}", lineNumber_,
        words.size(), element.name, itemIndex + 1, countsKnown ? "" : "at least ", needed));
}

/// Reads one item: scalars into values.scalar, the face list (if asked) into values.faceIndices;
/// every other list is skipped.
void PlyBodyReader::readItem(const PlyElement& element, std::uint64_t itemIndex,
                             std::optional<std::size_t> faceList, ItemValues& values) {
    values.faceIndices.clear();
    if (binary()) {
        readBinaryItem(element, itemIndex, faceList, values);
    } else {
        readAsciiItem(element, itemIndex, faceList, values);
    }
}

void PlyBodyReader::readBinaryItem(const PlyElement& element, std::uint64_t itemIndex,
                                   std::optional<std::size_t> faceList, ItemValues& values) {
    const auto load = [&](PlyType type) {
        const std::size_t size = plySizeOf(type);
        if (file_.size() - position_ < size) {
            failTruncated(element, itemIndex);
        }
        const double value = loadBinary(type, file_.data() + position_);
        position_ += size;
        return value;
    };
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (!property.isList) {
            values.scalar[p] = load(property.type);
            continue;
        }
        const std::uint64_t count = listLength(load(property.countType), element, itemIndex);
        const std::size_t itemSize = plySizeOf(property.type);
        if (count > (file_.size() - position_) / itemSize) {
            failTruncated(element, itemIndex);
        }
        if (faceList && *faceList == p) {
            for (std::uint64_t i = 0; i < count; ++i) {
                const double index = load(property.type);
                values.faceIndices.push_back(index >= 0.0 && index < 4294967295.0
                                                 ? static_cast<std::uint32_t>(index)
                                                 : kInvalidIndex);
            }
        } else {
            position_ += static_cast<std::size_t>(count) * itemSize;
        }
    }
}

void PlyBodyReader::readAsciiItem(const PlyElement& element, std::uint64_t itemIndex,
                                  std::optional<std::size_t> faceList, ItemValues& values) {
    if (!nextAsciiLine()) {
        failTruncated(element, itemIndex);
    }
    const auto next = [&] {
        const std::optional<double> value = nextAsciiValue(element, itemIndex);
        if (!value) {
            failAsciiLine(element, itemIndex);
        }
        return *value;
    };
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (!property.isList) {
            values.scalar[p] = next();
            continue;
        }
        const std::uint64_t count = listLength(next(), element, itemIndex);
        const bool keep = faceList && *faceList == p;
        for (std::uint64_t i = 0; i < count; ++i) {
            const double index = next();
            if (keep) {
                values.faceIndices.push_back(index >= 0.0 && index < 4294967295.0 &&
                                                     index == std::floor(index)
                                                 ? static_cast<std::uint32_t>(index)
                                                 : kInvalidIndex);
            }
        }
    }
    if (cursor_ != lineEnd_) {
        failAsciiLine(element, itemIndex);
    }
}

/// Like the PCD reader: lines after the last element are ignored, but not silently.
void PlyBodyReader::warnAboutAsciiLinesLeft() {
    std::size_t linesLeft = 0;
    while (nextAsciiLine()) {
        ++linesLeft;
    }
    if (linesLeft > 0) {
        const PlyElement& last = header_.elements.back();
        context_.warnings.push_back(
            fmt::format("ignored the {} PLY ascii line{} after the last element, the {} {} "
                        "items declared in the header",
                        linesLeft, linesLeft == 1 ? "" : "s", last.count, last.name));
    }
}

void PlyBodyReader::skipElement(const PlyElement& element) {
    if (element.properties.empty()) {
        return;  // items without properties occupy no bytes, however many are declared
    }
    if (const auto stride = element.fixedStride(); binary() && stride) {
        const std::size_t remaining = file_.size() - position_;
        if (*stride > 0 && element.count > remaining / *stride) {
            failTruncated(element, remaining / *stride);
        }
        position_ += static_cast<std::size_t>(element.count) * *stride;
        return;
    }
    ItemValues values;
    values.scalar.resize(element.properties.size());
    for (std::uint64_t i = 0; i < element.count; ++i) {
        readItem(element, i, std::nullopt, values);
    }
}

PointCloud PlyBodyReader::read() {
    const PlyElement* vertex = nullptr;
    const PlyElement* face = nullptr;
    std::size_t lastNeeded = 0;
    for (std::size_t e = 0; e < header_.elements.size(); ++e) {
        const PlyElement& element = header_.elements[e];
        if (element.name == "vertex" && vertex == nullptr) {
            vertex = &element;
            lastNeeded = e;
        } else if (element.name == "face" && face == nullptr) {
            face = &element;
            lastNeeded = e;
        }
    }
    if (vertex == nullptr) {
        throw Error("the PLY file has no 'vertex' element");
    }
    if (vertex->count > kMaxPoints) {
        throw Error(
            fmt::format("the PLY header declares {} vertices, more than the {} points "
                        "subscan can hold",
                        vertex->count, kMaxPoints));
    }
    const PlyVertexLayout layout = findPlyVertexLayout(*vertex);
    std::optional<std::size_t> faceList;
    if (face != nullptr) {
        faceList = findFaceList(*face);
        if (!faceList) {
            context_.warnings.push_back(
                "the PLY face element has no vertex_indices list; faces ignored");
            face = nullptr;
        }
    }

    // Never reserve more than the body could hold: a lying header must not allocate gigabytes.
    const std::size_t body = file_.size() - position_;
    const std::size_t minimumVertexBytes =
        binary() ? std::max<std::size_t>(1, vertex->fixedStride().value_or(1))
                 : 2 * vertex->properties.size();
    const std::size_t expected =
        static_cast<std::size_t>(std::min<std::uint64_t>(vertex->count, body / minimumVertexBytes));

    PointAttributes attributes;
    attributes.color = layout.color.has_value();
    attributes.normal = layout.normal.has_value();
    attributes.intensity = layout.intensity.has_value();
    PointCloudBuilder builder(attributes, expected, face != nullptr);
    if (context_.keepFilePrecision) {
        builder.keepPositionResiduals();
    }

    const auto colorType = [&](std::size_t index) { return vertex->properties[index].type; };
    const std::vector<std::size_t> colorChannels = layout.colorChannels();
    // Until the last vertex says whether 16-bit and float channels hold large values, each
    // vertex's colour is kept read both ways: 4 bytes a point, and only for such channels.
    const bool colorScaleOpen =
        std::any_of(colorChannels.begin(), colorChannels.end(), [&](std::size_t p) {
            return plyColorScale(colorType(p), false) != plyColorScale(colorType(p), true);
        });
    bool largeColorValues = false;
    std::vector<Rgba8> largeValueColors;
    const auto colorOf = [&](auto&& value, bool largeValues) {
        const auto channel = [&](std::size_t p) {
            return toColorChannel(value(p), plyColorScale(colorType(p), largeValues));
        };
        const auto& c = *layout.color;
        return Rgba8{channel(c[0]), channel(c[1]), channel(c[2]),
                     layout.alpha ? channel(*layout.alpha) : std::uint8_t{255}};
    };
    // Whether the kept vertices' red, green and blue used more than 8 bits, which the 8-bit
    // colour read from them loses: a 16-bit value other than an 8-bit one times 257 (lost when
    // the file's colour reads as 16-bit), or a 32-bit value over 255 (clamped).
    std::vector<std::size_t> wideIntegerColors;
    if (layout.color) {
        wideIntegerColors.assign(layout.color->begin(), layout.color->end());
        std::erase_if(wideIntegerColors, [&](std::size_t p) {
            return !isPlyInteger(colorType(p)) || plySizeOf(colorType(p)) == 1;
        });
    }
    bool wordColorBeyondBytes = false;
    bool widerColorClamped = false;
    const auto noteColorBeyondBytes = [&](auto&& value) {
        for (const std::size_t p : wideIntegerColors) {
            if (plySizeOf(colorType(p)) == 2) {
                wordColorBeyondBytes = wordColorBeyondBytes || colorWordNeedsSixteenBits(value(p));
            } else {
                widerColorClamped = widerColorClamped || value(p) > 255.0;
            }
        }
    };
    auto makeRecord = [&](auto&& value) {
        PointRecord record;
        record.position = {value(layout.position[0]), value(layout.position[1]),
                           value(layout.position[2])};
        if (layout.color) {
            record.color = colorOf(value, false);
        }
        if (layout.normal) {
            const auto& n = *layout.normal;
            record.normal = {saturateToFloat(value(n[0])), saturateToFloat(value(n[1])),
                             saturateToFloat(value(n[2]))};
        }
        if (layout.intensity) {
            record.intensity = saturateToFloat(value(*layout.intensity));
        }
        return record;
    };
    const auto addVertex = [&](auto&& value) {
        const std::size_t kept = builder.validPoints();
        builder.add(makeRecord(value));
        if (builder.validPoints() > kept) {
            noteColorBeyondBytes(value);
        }
        if (!colorScaleOpen) {
            return;
        }
        for (const std::size_t p : colorChannels) {
            largeColorValues = largeColorValues || isLargePlyColorValue(colorType(p), value(p));
        }
        if (builder.validPoints() > kept) {
            largeValueColors.push_back(colorOf(value, true));
        }
    };
    constexpr std::uint64_t kProgressEvery = 1 << 16;

    // Ascii bodies are read to their end, to tell of lines that no element declares.
    const std::size_t lastRead = binary() ? lastNeeded : header_.elements.size() - 1;
    for (std::size_t e = 0; e <= lastRead; ++e) {
        const PlyElement& element = header_.elements[e];
        if (&element == vertex) {
            const auto stride = vertex->fixedStride();
            if (binary() && stride) {
                // Fast path: fixed-size records, one bounds check for the whole element.
                const std::size_t available = (file_.size() - position_) / *stride;
                if (vertex->count > available) {
                    failTruncated(*vertex, available);
                }
                std::vector<std::size_t> offsets(vertex->properties.size());
                for (std::size_t p = 1; p < offsets.size(); ++p) {
                    offsets[p] = offsets[p - 1] + plySizeOf(vertex->properties[p - 1].type);
                }
                for (std::uint64_t i = 0; i < vertex->count; ++i) {
                    const std::byte* record = file_.data() + position_;
                    addVertex([&](std::size_t p) {
                        return loadBinary(vertex->properties[p].type, record + offsets[p]);
                    });
                    position_ += *stride;
                    if (i % kProgressEvery == 0) {
                        context_.reportProgress(position_, file_.size());
                    }
                }
            } else {
                ItemValues values;
                values.scalar.resize(vertex->properties.size());
                // Text can say what binary cannot: an integer colour channel's 300 or 1.7 was
                // clamped or rounded silently. Properties that are not read are not judged.
                std::vector<std::size_t> integerChannels = colorChannels;
                std::erase_if(integerChannels,
                              [&](std::size_t p) { return !isPlyInteger(colorType(p)); });
                for (std::uint64_t i = 0; i < vertex->count; ++i) {
                    readItem(*vertex, i, std::nullopt, values);
                    for (const std::size_t p : integerChannels) {
                        if (!plyTypeHolds(colorType(p), values.scalar[p])) {
                            throw Error(fmt::format(
                                "the PLY body's vertex {} has {} = {}, which its integer type "
                                "cannot hold",
                                i + 1, vertex->properties[p].name, values.scalar[p]));
                        }
                    }
                    addVertex([&](std::size_t p) { return values.scalar[p]; });
                    if (i % kProgressEvery == 0) {
                        context_.reportProgress(position_, file_.size());
                    }
                }
            }
        } else if (&element == face) {
            ItemValues values;
            values.scalar.resize(face->properties.size());
            std::uint64_t skippedPolygons = 0;
            for (std::uint64_t i = 0; i < face->count; ++i) {
                readItem(*face, i, faceList, values);
                const auto& indices = values.faceIndices;
                for (const std::uint32_t index : indices) {
                    if (index == kInvalidIndex || index >= vertex->count) {
                        throw Error(fmt::format(
                            "PLY face {} refers to a vertex index outside 0..{} (the file has {} "
                            "vertices)",
                            i + 1, vertex->count == 0 ? 0 : vertex->count - 1, vertex->count));
                    }
                }
                if (indices.size() < 3) {
                    ++skippedPolygons;
                    continue;
                }
                for (std::size_t k = 1; k + 1 < indices.size(); ++k) {
                    builder.addTriangle({indices[0], indices[k], indices[k + 1]});
                }
                if (i % kProgressEvery == 0) {
                    context_.reportProgress(position_, file_.size());
                }
            }
            if (skippedPolygons > 0) {
                context_.warnings.push_back(fmt::format(
                    "skipped {} PLY faces with fewer than 3 vertices", skippedPolygons));
            }
        } else {
            skipElement(element);
        }
    }
    if (!binary()) {
        warnAboutAsciiLinesLeft();
    }
    context_.reportProgress(file_.size(), file_.size());
    PointCloud cloud = builder.finish(context_.warnings);
    cloud.doubleCoordinates =
        std::any_of(layout.position.begin(), layout.position.end(), [&](std::size_t property) {
            return vertex->properties[property].type == PlyType::Float64;
        });
    if (largeColorValues) {
        cloud.colors = std::move(largeValueColors);
    }
    cloud.colorCutTo8Bits = (largeColorValues && wordColorBeyondBytes) || widerColorClamped;
    return cloud;
}

}  // namespace

PointCloud readPly(std::span<const std::byte> file, ReadContext& context) {
    const std::string_view text(reinterpret_cast<const char*>(file.data()), file.size());
    const PlyHeader header = parsePlyHeader(text);
    static constexpr std::array kEncodingNames{"ascii", "binary_little_endian",
                                               "binary_big_endian"};
    context.formatDetail =
        fmt::format("PLY {} {}", header.version, kEncodingNames[static_cast<int>(header.encoding)]);
    PlyBodyReader reader(header, file.subspan(header.bodyOffset), context);
    return reader.read();
}

}  // namespace subscan
