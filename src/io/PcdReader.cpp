#include "io/PcdReader.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <lzf.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/TextParsing.h"

namespace subscan {

namespace {

enum class PcdDataKind { Ascii, Binary, BinaryCompressed };
constexpr std::array kDataKindNames{"ascii", "binary", "binary_compressed"};

enum class PcdType : std::uint8_t {
    Int8,
    Int16,
    Int32,
    Int64,
    UInt8,
    UInt16,
    UInt32,
    UInt64,
    Float32,
    Float64,
};

struct PcdField {
    std::string name;
    PcdType type = PcdType::Float32;
    std::uint64_t size = 4;   // bytes of one value
    std::uint64_t count = 1;  // values per point
    char typeLetter = 'F';

    /// PCL's name for padding bytes that keep binary records aligned.
    bool isPadding() const { return name == "_"; }
};

struct PcdHeader {
    std::string version;
    std::vector<PcdField> fields;
    std::uint64_t width = 0;
    std::uint64_t height = 1;
    std::uint64_t points = 0;
    PcdDataKind dataKind = PcdDataKind::Ascii;
    std::size_t bodyOffset = 0;
    std::size_t headerLines = 0;       // so ascii errors can name the line in the whole file
    std::uint64_t stride = 0;          // Σ SIZE × COUNT: bytes per point in binary data
    std::uint64_t valuesPerPoint = 0;  // Σ COUNT: numbers per line in ascii data
    glm::dvec3 viewpoint{0.0};         // the sensor's position (VIEWPOINT; the default is 0 0 0)
    bool viewpointGiven = false;
};

/// Bytes and numbers per point are capped far above any real layout, so that every product of
/// them with a 32-bit point count stays inside 64 bits.
constexpr std::uint64_t kMaxPointBytes = std::uint64_t{1} << 30;

std::optional<std::uint64_t> parseUnsigned(std::string_view word) {
    std::uint64_t value = 0;
    const char* last = word.data() + word.size();
    const auto [end, ec] = std::from_chars(word.data(), last, value);
    if (ec != std::errc() || end != last) {
        return std::nullopt;
    }
    return value;
}

std::optional<PcdType> typeFor(char letter, std::uint64_t size) {
    switch (letter) {
        case 'F':
            return size == 4   ? std::optional(PcdType::Float32)
                   : size == 8 ? std::optional(PcdType::Float64)
                               : std::nullopt;
        case 'I':
        case 'U': {
            const bool isSigned = letter == 'I';
            switch (size) {
                case 1:
                    return isSigned ? PcdType::Int8 : PcdType::UInt8;
                case 2:
                    return isSigned ? PcdType::Int16 : PcdType::UInt16;
                case 4:
                    return isSigned ? PcdType::Int32 : PcdType::UInt32;
                case 8:
                    return isSigned ? PcdType::Int64 : PcdType::UInt64;
                default:
                    return std::nullopt;
            }
        }
        default:
            return std::nullopt;
    }
}

bool isFloat(PcdType type) {
    return type == PcdType::Float32 || type == PcdType::Float64;
}

/// One header line split into words; the keyword is words[0].
struct HeaderLine {
    std::string_view text;
    std::size_t number = 0;
    std::vector<std::string_view> words;
};

[[noreturn]] void failLine(const HeaderLine& line, std::string_view what) {
    throw Error(
        fmt::format("PCD header line {} {} {}", line.number, quoteForMessage(line.text, 60), what));
}

/// The header as written, before its lines are checked against each other.
struct RawHeader {
    std::optional<HeaderLine> version, fields, sizes, types, counts, width, height, points,
        viewpoint;
};

/// Far longer than any real header line (FIELDS of a few hundred names).
constexpr std::size_t kMaxHeaderLineBytes = 1 << 20;

/// Reads header lines up to and including DATA.
RawHeader readHeaderLines(std::string_view file, PcdHeader& header) {
    RawHeader raw;
    std::size_t position = 0;
    std::size_t lineNumber = 0;
    while (true) {
        if (position >= file.size()) {
            throw Error("the PCD header has no DATA line (file truncated, or not a PCD file?)");
        }
        const std::size_t end = std::min(file.find('\n', position), file.size());
        HeaderLine line;
        line.text = file.substr(position, end - position);
        line.number = ++lineNumber;
        position = std::min(end + 1, file.size());
        const std::size_t firstCharacter = line.text.find_first_not_of(" \t\r\v\f");
        if (firstCharacter == std::string_view::npos || line.text[firstCharacter] == '#') {
            continue;
        }
        if (line.text.size() > kMaxHeaderLineBytes) {
            // Splitting a binary file's first "line" into words could take gigabytes.
            failLine(
                line,
                fmt::format(
                    "is longer than {} bytes, too long for a PCD header line (not a PCD file?)",
                    kMaxHeaderLineBytes));
        }
        line.words = splitWords(line.text);
        const std::string_view keyword = line.words[0];
        auto store = [&](std::optional<HeaderLine>& slot) {
            if (slot) {
                failLine(line, fmt::format("repeats {}, already given on line {}", keyword,
                                           slot->number));
            }
            slot = line;
        };
        if (keyword == "DATA") {
            if (line.words.size() != 2) {
                failLine(line,
                         "should read 'DATA ascii', 'DATA binary' or 'DATA binary_compressed'");
            }
            const auto kind =
                std::find(kDataKindNames.begin(), kDataKindNames.end(), line.words[1]);
            if (kind == kDataKindNames.end()) {
                failLine(
                    line,
                    "names an unknown data kind (expected ascii, binary or binary_compressed)");
            }
            header.dataKind = static_cast<PcdDataKind>(kind - kDataKindNames.begin());
            header.bodyOffset = position;
            header.headerLines = lineNumber;
            return raw;
        }
        if (keyword == "VERSION") {
            store(raw.version);
        } else if (keyword == "FIELDS" || keyword == "COLUMNS") {  // COLUMNS: PCD before 0.5
            store(raw.fields);
        } else if (keyword == "SIZE") {
            store(raw.sizes);
        } else if (keyword == "TYPE") {
            store(raw.types);
        } else if (keyword == "COUNT") {
            store(raw.counts);
        } else if (keyword == "WIDTH") {
            store(raw.width);
        } else if (keyword == "HEIGHT") {
            store(raw.height);
        } else if (keyword == "POINTS") {
            store(raw.points);
        } else if (keyword == "VIEWPOINT") {
            store(raw.viewpoint);
        } else {
            failLine(line, "is not a PCD header keyword");
        }
    }
}

std::optional<std::uint64_t> readCount(const std::optional<HeaderLine>& line) {
    if (!line) {
        return std::nullopt;
    }
    if (line->words.size() != 2) {
        failLine(*line, fmt::format("should read '{} <number>'", line->words[0]));
    }
    const auto value = parseUnsigned(line->words[1]);
    if (!value) {
        failLine(*line, "has a value that is not a non-negative integer");
    }
    return value;
}

/// The values of SIZE, TYPE or COUNT, one per field; empty when the line is absent.
std::vector<std::string_view> perFieldValues(const std::optional<HeaderLine>& line,
                                             std::size_t fieldCount) {
    if (!line) {
        return {};
    }
    const std::size_t values = line->words.size() - 1;
    if (values != fieldCount) {
        throw Error(fmt::format("the PCD header lists {} FIELDS but {} {} values (line {})",
                                fieldCount, values, line->words[0], line->number));
    }
    return {line->words.begin() + 1, line->words.end()};
}

std::vector<PcdField> parseFields(const RawHeader& raw) {
    if (!raw.fields) {
        throw Error("the PCD header has no FIELDS line");
    }
    const std::size_t fieldCount = raw.fields->words.size() - 1;
    if (fieldCount == 0) {
        failLine(*raw.fields, "names no fields");
    }
    // Files older than PCD 0.7 may leave out SIZE, TYPE and COUNT; PCL then reads every field
    // as one float, and so do we.
    const auto sizes = perFieldValues(raw.sizes, fieldCount);
    const auto types = perFieldValues(raw.types, fieldCount);
    const auto counts = perFieldValues(raw.counts, fieldCount);

    std::vector<PcdField> fields(fieldCount);
    for (std::size_t i = 0; i < fieldCount; ++i) {
        PcdField& field = fields[i];
        field.name = std::string(raw.fields->words[i + 1]);
        const std::string quotedName = quoteForMessage(field.name);
        if (!sizes.empty()) {
            const auto size = parseUnsigned(sizes[i]);
            if (!size || (*size != 1 && *size != 2 && *size != 4 && *size != 8)) {
                throw Error(
                    fmt::format("the PCD field {} has SIZE {}, but a SIZE must be 1, 2, 4 or 8",
                                quotedName, quoteForMessage(sizes[i])));
            }
            field.size = *size;
        }
        if (!types.empty()) {
            if (types[i].size() != 1 || !typeFor(types[i][0], 4)) {
                throw Error(
                    fmt::format("the PCD field {} has the unknown TYPE {} (expected F, I or U)",
                                quotedName, quoteForMessage(types[i])));
            }
            field.typeLetter = types[i][0];
        }
        const auto type = typeFor(field.typeLetter, field.size);
        if (!type) {
            throw Error(
                fmt::format("the PCD field {} has TYPE F with SIZE {}, but floats have SIZE 4 or 8",
                            quotedName, field.size));
        }
        field.type = *type;
        if (!counts.empty()) {
            const auto count = parseUnsigned(counts[i]);
            if (!count) {
                throw Error(fmt::format(
                    "the PCD field {} has COUNT {}, which is not a non-negative integer",
                    quotedName, quoteForMessage(counts[i])));
            }
            field.count = *count;
        }
    }
    return fields;
}

std::string formatVersion(const std::optional<HeaderLine>& line) {
    if (!line || line->words.size() < 2) {
        return {};
    }
    const std::string_view version = line->words[1];
    // Old files write ".5" for 0.5.
    return version.starts_with('.') ? fmt::format("0{}", version) : std::string(version);
}

PcdHeader parseHeader(std::string_view file) {
    PcdHeader header;
    const RawHeader raw = readHeaderLines(file, header);
    header.version = formatVersion(raw.version);
    header.fields = parseFields(raw);

    for (const PcdField& field : header.fields) {
        // COUNT comes first: SIZE (at most 8) times an unchecked COUNT could wrap around.
        if (field.count > kMaxPointBytes ||
            header.stride + field.size * field.count > kMaxPointBytes) {
            throw Error(fmt::format(
                "the PCD fields add up to more than {} bytes per point (is a COUNT wrong?)",
                kMaxPointBytes));
        }
        header.stride += field.size * field.count;
        header.valuesPerPoint += field.count;
    }

    if (raw.viewpoint) {
        // VIEWPOINT tx ty tz qw qx qy qz: the sensor's position and orientation. The points are
        // not moved by it (PCL keeps them as stored); only the position is used, for the
        // sensor view (an organised cloud's own grid gives its orientation more reliably).
        const HeaderLine& line = *raw.viewpoint;
        std::array<double, 7> values{};
        bool valid = line.words.size() == 8;
        for (std::size_t i = 0; valid && i < values.size(); ++i) {
            const std::string_view word = line.words[i + 1];
            valid = parseNumber(word.data(), word.data() + word.size(), values[i]) ==
                        word.data() + word.size() &&
                    std::isfinite(values[i]);
        }
        if (!valid) {
            failLine(line, "should read 'VIEWPOINT tx ty tz qw qx qy qz' with finite numbers");
        }
        header.viewpoint = {values[0], values[1], values[2]};
        header.viewpointGiven = true;
    }
    const auto width = readCount(raw.width);
    const auto height = readCount(raw.height);
    const auto points = readCount(raw.points);
    if (height && !width) {
        throw Error("the PCD header gives HEIGHT but no WIDTH");
    }
    if (!width && !points) {
        throw Error("the PCD header gives neither WIDTH nor POINTS");
    }
    // PCD 0.5 may leave out POINTS (then WIDTH x HEIGHT) or WIDTH/HEIGHT (then POINTS x 1).
    header.width = width.value_or(points.value_or(0));
    header.height = height.value_or(1);
    if (header.height != 0 &&
        header.width > std::numeric_limits<std::uint64_t>::max() / header.height) {
        throw Error(
            fmt::format("the PCD WIDTH {} x HEIGHT {} is too large", header.width, header.height));
    }
    const std::uint64_t gridPoints = header.width * header.height;
    header.points = points.value_or(gridPoints);
    if (gridPoints != header.points) {
        throw Error(fmt::format(
            "the PCD header's WIDTH x HEIGHT ({} x {} = {}) does not equal its POINTS ({})",
            header.width, header.height, gridPoints, header.points));
    }
    if (header.points > kMaxPoints) {
        throw Error(fmt::format(
            "the PCD header declares {} points, more than the {} points subscan can hold",
            header.points, kMaxPoints));
    }
    return header;
}

bool equalsIgnoringCase(std::string_view a, std::string_view b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](char x, char y) {
        return std::tolower(static_cast<unsigned char>(x)) ==
               std::tolower(static_cast<unsigned char>(y));
    });
}

/// Which fields hold what we keep (indices into PcdHeader::fields).
struct FieldLayout {
    std::array<std::size_t, 3> position{};
    std::optional<std::size_t> packedColor;  // rgb or rgba: one 32-bit word 0xAARRGGBB
    bool packedHasAlpha = false;
    std::optional<std::array<std::size_t, 3>> colorChannels;  // separate red, green, blue
    std::optional<std::size_t> alphaChannel;
    std::optional<std::array<std::size_t, 3>> normal;
    std::optional<std::size_t> intensity;

    /// Every field a point needs decoded, each once.
    std::vector<std::size_t> usedFields() const;
};

std::vector<std::size_t> FieldLayout::usedFields() const {
    std::vector<std::size_t> used(position.begin(), position.end());
    auto addAll = [&](const auto& indices) {
        if (indices) {
            used.insert(used.end(), indices->begin(), indices->end());
        }
    };
    auto addOne = [&](const std::optional<std::size_t>& index) {
        if (index) {
            used.push_back(*index);
        }
    };
    addOne(packedColor);
    addAll(colorChannels);
    addOne(alphaChannel);
    addAll(normal);
    addOne(intensity);
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    return used;
}

class FieldFinder {
  public:
    FieldFinder(const std::vector<PcdField>& fields, std::vector<std::string>& warnings)
        : fields_(fields), warnings_(warnings) {}

    /// The field of that name (PCL's lower case preferred; PDAL writes "X", "Red", ...),
    /// or nullopt when there is none.
    std::optional<std::size_t> find(std::string_view name) const {
        for (std::size_t i = 0; i < fields_.size(); ++i) {
            if (fields_[i].name == name) {
                return i;
            }
        }
        for (std::size_t i = 0; i < fields_.size(); ++i) {
            if (equalsIgnoringCase(fields_[i].name, name)) {
                return i;
            }
        }
        return std::nullopt;
    }

    /// Like find(), but a field holding several values per point is skipped with a warning.
    std::optional<std::size_t> findSingle(std::string_view name) const {
        const auto index = find(name);
        if (index && fields_[*index].count != 1) {
            warnings_.push_back(fmt::format(
                "ignored the PCD field {}: it has COUNT {}, but one value per point was expected",
                quoteForMessage(fields_[*index].name), fields_[*index].count));
            return std::nullopt;
        }
        return index;
    }

    std::optional<std::array<std::size_t, 3>> findTriple(std::string_view a, std::string_view b,
                                                         std::string_view c) const {
        const auto ia = findSingle(a), ib = findSingle(b), ic = findSingle(c);
        if (ia && ib && ic) {
            return std::array{*ia, *ib, *ic};
        }
        return std::nullopt;
    }

  private:
    const std::vector<PcdField>& fields_;
    std::vector<std::string>& warnings_;
};

FieldLayout selectFields(const PcdHeader& header, std::vector<std::string>& warnings) {
    const FieldFinder finder(header.fields, warnings);
    FieldLayout layout;
    for (int axis = 0; axis < 3; ++axis) {
        const std::string_view name = std::array{"x", "y", "z"}[axis];
        const auto index = finder.find(name);
        if (!index) {
            throw Error(fmt::format("the PCD file has no '{}' field", name));
        }
        const PcdField& field = header.fields[*index];
        if (field.count != 1) {
            throw Error(fmt::format(
                "the PCD field {} has COUNT {}, but a coordinate must be one value per point",
                quoteForMessage(field.name), field.count));
        }
        layout.position[axis] = *index;
    }

    for (const std::string_view name : {"rgba", "rgb"}) {
        const auto index = finder.findSingle(name);
        if (!index) {
            continue;
        }
        if (header.fields[*index].size != 4) {
            warnings.push_back(fmt::format(
                "ignored the PCD field {}: a packed colour has SIZE 4, not {}",
                quoteForMessage(header.fields[*index].name), header.fields[*index].size));
            continue;
        }
        layout.packedColor = index;
        layout.packedHasAlpha = name == "rgba";
        break;
    }
    if (!layout.packedColor) {
        layout.colorChannels = finder.findTriple("red", "green", "blue");
        if (layout.colorChannels) {
            layout.alphaChannel = finder.findSingle("alpha");
        }
    }
    layout.normal = finder.findTriple("normal_x", "normal_y", "normal_z");
    if (!layout.normal) {
        layout.normal = finder.findTriple("nx", "ny", "nz");
    }
    layout.intensity = finder.findSingle("intensity");
    return layout;
}

double loadValue(PcdType type, const std::byte* p) {
    switch (type) {
        case PcdType::Int8:
            return loadLittleEndian<std::int8_t>(p);
        case PcdType::Int16:
            return loadLittleEndian<std::int16_t>(p);
        case PcdType::Int32:
            return loadLittleEndian<std::int32_t>(p);
        case PcdType::Int64:
            return static_cast<double>(loadLittleEndian<std::int64_t>(p));
        case PcdType::UInt8:
            return loadLittleEndian<std::uint8_t>(p);
        case PcdType::UInt16:
            return loadLittleEndian<std::uint16_t>(p);
        case PcdType::UInt32:
            return loadLittleEndian<std::uint32_t>(p);
        case PcdType::UInt64:
            return static_cast<double>(loadLittleEndian<std::uint64_t>(p));
        case PcdType::Float32:
            return loadLittleEndian<float>(p);
        case PcdType::Float64:
            return loadLittleEndian<double>(p);
    }
    return 0.0;
}

/// Packed rgb/rgba holds 8 bits a channel by definition: nothing in it is cut to 8 bits.
Rgba8 unpackColor(std::uint32_t bits, bool hasAlpha) {
    return {static_cast<std::uint8_t>(bits >> 16), static_cast<std::uint8_t>(bits >> 8),
            static_cast<std::uint8_t>(bits),
            hasAlpha ? static_cast<std::uint8_t>(bits >> 24) : std::uint8_t{255}};
}

/// Separate colour channels can only be scaled once all of them are known: PDAL writes 16-bit
/// channels that hold either 0..255 (as many LAS files do) or 0..65535. Their raw values wait
/// here, one entry per kept point, until finish().
class ChannelColors {
  public:
    ChannelColors(const PcdHeader& header, const FieldLayout& layout) {
        for (int channel = 0; channel < 3; ++channel) {
            types_[channel] = header.fields[(*layout.colorChannels)[channel]].type;
        }
        // Without an alpha field add() gets 255, which UInt8 keeps as it is.
        types_[3] = layout.alphaChannel ? header.fields[*layout.alphaChannel].type : PcdType::UInt8;
    }

    void add(const std::array<double, 4>& values) {
        std::array<float, 4> kept{};
        for (int channel = 0; channel < 4; ++channel) {
            const double value = values[channel];
            kept[channel] = saturateToFloat(value);
            if (isWide(types_[channel]) && value > 255.0) {
                wideValuesAbove8Bits_ = true;
            }
            if (channel < 3 && isWide(types_[channel]) && value > 0.0 &&
                (value > 65535.0 || colorWordNeedsSixteenBits(value))) {
                wideValueBeyondBytes_ = true;
            }
        }
        values_.push_back(kept);
    }

    /// Whether the red, green and blue of the kept points used more than 8 bits, which
    /// applyTo's 8-bit colour loses: read as 16-bit, a value other than an 8-bit one times 257,
    /// or one over 65535 (clamped).
    bool cutTo8Bits() const { return wideValuesAbove8Bits_ && wideValueBeyondBytes_; }

    void applyTo(std::vector<Rgba8>& colors) const {
        for (std::size_t i = 0; i < colors.size() && i < values_.size(); ++i) {
            const auto& v = values_[i];
            colors[i] = {toChannel(v[0], types_[0]), toChannel(v[1], types_[1]),
                         toChannel(v[2], types_[2]), toChannel(v[3], types_[3])};
        }
    }

  private:
    static bool isWide(PcdType type) {
        return !isFloat(type) && type != PcdType::Int8 && type != PcdType::UInt8;
    }

    std::uint8_t toChannel(float value, PcdType type) const {
        double scaled = value;
        if (isFloat(type)) {
            scaled = value * 255.0;  // float colours run from 0 to 1
        } else if (isWide(type) && wideValuesAbove8Bits_) {
            scaled = value / 257.0;  // 65535 -> 255
        }
        if (!(scaled > 0.0)) {
            return 0;  // also NaN
        }
        return static_cast<std::uint8_t>(std::min(255.0, scaled + 0.5));
    }

    std::array<PcdType, 4> types_{};
    bool wideValuesAbove8Bits_ = false;
    bool wideValueBeyondBytes_ = false;
    std::vector<std::array<float, 4>> values_;
};

/// Turns decoded field values into points for the builder.
class PointSink {
  public:
    PointSink(const PcdHeader& header, const FieldLayout& layout, std::size_t expectedPoints,
              bool keepFilePrecision)
        : layout_(layout),
          builder_(PointAttributes{layout.packedColor || layout.colorChannels,
                                   layout.normal.has_value(), layout.intensity.has_value()},
                   expectedPoints),
          organised_(header.height > 1) {
        if (layout.colorChannels) {
            channelColors_.emplace(header, layout);
        }
        if (keepFilePrecision) {
            builder_.keepPositionResiduals();
        }
    }

    /// `valueOf(field)`: the field's value as a number; `bitsOf(field)`: its 32 bits (packed
    /// colours only).
    template <class ValueOf, class BitsOf>
    void add(const ValueOf& valueOf, const BitsOf& bitsOf) {
        PointRecord record;
        record.position = {valueOf(layout_.position[0]), valueOf(layout_.position[1]),
                           valueOf(layout_.position[2])};
        if (layout_.packedColor) {
            record.color = unpackColor(bitsOf(*layout_.packedColor), layout_.packedHasAlpha);
        }
        if (layout_.normal) {
            const auto& n = *layout_.normal;
            record.normal = {saturateToFloat(valueOf(n[0])), saturateToFloat(valueOf(n[1])),
                             saturateToFloat(valueOf(n[2]))};
        }
        if (layout_.intensity) {
            record.intensity = saturateToFloat(valueOf(*layout_.intensity));
        }
        const std::size_t keptBefore = builder_.validPoints();
        builder_.add(record);
        const std::uint32_t recordNumber = records_++;
        if (builder_.validPoints() == keptBefore) {
            return;
        }
        if (organised_) {
            cellOfPoint_.push_back(recordNumber);
        }
        if (channelColors_) {
            const auto& c = *layout_.colorChannels;
            channelColors_->add({valueOf(c[0]), valueOf(c[1]), valueOf(c[2]),
                                 layout_.alphaChannel ? valueOf(*layout_.alphaChannel) : 255.0});
        }
    }

    PointCloud finish(std::vector<std::string>& warnings) {
        PointCloud cloud = builder_.finish(warnings);
        if (channelColors_) {
            channelColors_->applyTo(cloud.colors);
            cloud.colorCutTo8Bits = channelColors_->cutTo8Bits();
        }
        return cloud;
    }

    /// For an organised cloud, the grid cell (record number) of each point kept.
    std::vector<std::uint32_t> takeCellOfPoint() { return std::move(cellOfPoint_); }

  private:
    const FieldLayout& layout_;
    PointCloudBuilder builder_;
    std::optional<ChannelColors> channelColors_;
    bool organised_ = false;
    std::uint32_t records_ = 0;  // PCD point counts fit 32 bits (kMaxPoints)
    std::vector<std::uint32_t> cellOfPoint_;
};

constexpr std::uint64_t kProgressEvery = 1 << 16;

/// Packed colours in ascii: PCL writes an F `rgb` as the integer value of its bits (older
/// versions wrote the float itself, which prints as an integer only for unusual alpha bytes).
std::optional<std::uint32_t> parsePackedColor(std::string_view token, PcdType type) {
    if (const auto integer = parseUnsigned(token); integer && *integer <= 0xFFFFFFFFu) {
        return static_cast<std::uint32_t>(*integer);
    }
    double value = 0.0;
    const char* last = token.data() + token.size();
    if (parseNumber(token.data(), last, value) != last) {
        return std::nullopt;
    }
    if (isFloat(type)) {
        return std::bit_cast<std::uint32_t>(saturateToFloat(value));
    }
    // A signed I field wraps: -16777216 is 0xFF000000.
    if (value >= -2147483648.0 && value < 4294967296.0) {
        return static_cast<std::uint32_t>(static_cast<std::int64_t>(value));
    }
    return std::nullopt;
}

void readAscii(std::string_view body, const PcdHeader& header, const FieldLayout& layout,
               PointSink& sink, ReadContext& context) {
    struct WantedValue {
        std::uint64_t valueIndex;  // position of the value on its line
        std::size_t field;
    };
    std::vector<std::uint64_t> firstValueOfField(header.fields.size());
    for (std::size_t f = 1; f < header.fields.size(); ++f) {
        firstValueOfField[f] = firstValueOfField[f - 1] + header.fields[f - 1].count;
    }
    std::vector<WantedValue> wanted;
    for (const std::size_t field : layout.usedFields()) {
        wanted.push_back({firstValueOfField[field], field});
    }
    std::vector<double> values(header.fields.size());
    std::vector<std::uint32_t> bits(header.fields.size());

    std::size_t position = 0;
    std::size_t lineNumber = header.headerLines;
    for (std::uint64_t point = 0; point < header.points;) {
        if (position >= body.size()) {
            throw Error(
                fmt::format("the PCD ascii data ends after {} of the {} points declared in the "
                            "header (file truncated, or POINTS is wrong)",
                            point, header.points));
        }
        const std::size_t end = std::min(body.find('\n', position), body.size());
        const std::string_view line = body.substr(position, end - position);
        position = end + 1;
        ++lineNumber;

        std::uint64_t valueIndex = 0;
        std::size_t nextWanted = 0;
        std::size_t i = 0;
        while (valueIndex < header.valuesPerPoint) {
            while (i < line.size() && isWhitespace(line[i])) {
                ++i;
            }
            if (i == line.size()) {
                break;
            }
            const std::size_t tokenStart = i;
            while (i < line.size() && !isWhitespace(line[i])) {
                ++i;
            }
            if (nextWanted < wanted.size() && wanted[nextWanted].valueIndex == valueIndex) {
                const std::string_view token = line.substr(tokenStart, i - tokenStart);
                const std::size_t field = wanted[nextWanted].field;
                bool parsed = false;
                if (layout.packedColor == field) {
                    const auto packed = parsePackedColor(token, header.fields[field].type);
                    parsed = packed.has_value();
                    bits[field] = packed.value_or(0);
                } else {
                    const char* last = token.data() + token.size();
                    parsed = parseNumber(token.data(), last, values[field]) == last;
                }
                if (!parsed) {
                    throw Error(fmt::format("PCD line {} has the non-numeric value {}", lineNumber,
                                            quoteForMessage(token)));
                }
                ++nextWanted;
            }
            ++valueIndex;
        }
        if (valueIndex == 0) {
            continue;  // blank lines carry no point
        }
        if (valueIndex < header.valuesPerPoint) {
            throw Error(fmt::format("PCD line {} has {} values, but the header's fields need {}",
                                    lineNumber, valueIndex, header.valuesPerPoint));
        }
        sink.add([&](std::size_t field) { return values[field]; },
                 [&](std::size_t field) { return bits[field]; });
        ++point;
        if (point % kProgressEvery == 0) {
            context.reportProgress(point, header.points);
        }
    }
    const std::string_view rest = body.substr(std::min(position, body.size()));
    if (!std::all_of(rest.begin(), rest.end(), isWhitespace)) {
        context.warnings.push_back(
            fmt::format("ignored the PCD ascii lines after the {} points declared in the header",
                        header.points));
    }
}

/// Decodes `header.points` points from binary data: row-major (binary) or column-major
/// (binary_compressed). `data` must hold them all; the caller checked its size once.
void readBinaryPoints(std::span<const std::byte> data, const PcdHeader& header, bool columnMajor,
                      bool paddingStored, PointSink& sink, ReadContext& context) {
    // Every field's value of point i lies at base + i * step.
    struct FieldAccess {
        const std::byte* base = nullptr;
        std::size_t step = 0;
        PcdType type = PcdType::Float32;
    };
    std::vector<FieldAccess> access(header.fields.size());
    std::size_t offset = 0;
    for (std::size_t f = 0; f < header.fields.size(); ++f) {
        const PcdField& field = header.fields[f];
        const std::size_t fieldBytes = field.size * field.count;
        access[f].type = field.type;
        access[f].base = data.data() + offset;
        access[f].step = columnMajor ? fieldBytes : header.stride;
        if (field.isPadding() && !paddingStored) {
            continue;
        }
        offset += columnMajor ? fieldBytes * header.points : fieldBytes;
    }

    for (std::size_t i = 0; i < header.points; ++i) {
        sink.add(
            [&](std::size_t f) {
                return loadValue(access[f].type, access[f].base + i * access[f].step);
            },
            [&](std::size_t f) {
                return loadLittleEndian<std::uint32_t>(access[f].base + i * access[f].step);
            });
        if ((i + 1) % kProgressEvery == 0) {
            context.reportProgress(i + 1, header.points);
        }
    }
}

void readBinary(std::span<const std::byte> body, const PcdHeader& header, PointSink& sink,
                ReadContext& context) {
    const std::uint64_t available = body.size() / header.stride;
    if (header.points > available) {
        throw Error(
            fmt::format("the PCD binary data holds {} of the {} points declared in the header "
                        "(file truncated, or POINTS is wrong)",
                        available, header.points));
    }
    readBinaryPoints(body, header, false, true, sink, context);
}

/// A 3-byte LZF back reference expands to at most 264 bytes, the most output per input byte LZF
/// can produce: a block that claims more than 88 times its compressed size is corrupt.
constexpr std::uint64_t kLongestLzfReference = 264;
constexpr std::uint64_t kMaxLzfExpansion = kLongestLzfReference / 3;
constexpr std::uint64_t kLzfSizeHeaderBytes = 8;

void readBinaryCompressed(std::span<const std::byte> body, const PcdHeader& header, PointSink& sink,
                          ReadContext& context) {
    if (header.points == 0) {
        return;  // writers differ in what they store for no points; there is nothing to read
    }
    if (body.size() < kLzfSizeHeaderBytes) {
        throw Error(
            "the PCD binary_compressed data ends inside its 8-byte size header (file truncated?)");
    }
    const std::uint32_t compressedSize = loadLittleEndian<std::uint32_t>(body.data());
    const std::uint32_t uncompressedSize = loadLittleEndian<std::uint32_t>(body.data() + 4);
    if (compressedSize > body.size() - kLzfSizeHeaderBytes) {
        throw Error(
            fmt::format("the PCD binary_compressed data should have {} compressed bytes, but only "
                        "{} follow (file truncated?)",
                        compressedSize, body.size() - kLzfSizeHeaderBytes));
    }
    // points <= 2^32 and stride <= 2^30: the products fit in 64 bits.
    const std::uint64_t expectedSize = header.points * header.stride;
    bool paddingStored = true;
    if (uncompressedSize != expectedSize) {
        // PCL's reader expects no columns for '_' padding fields; accept that layout too.
        std::uint64_t unpaddedStride = header.stride;
        for (const PcdField& field : header.fields) {
            if (field.isPadding()) {
                unpaddedStride -= field.size * field.count;
            }
        }
        paddingStored = false;
        if (unpaddedStride == header.stride || uncompressedSize != header.points * unpaddedStride) {
            throw Error(fmt::format(
                "the PCD binary_compressed data unpacks to {} bytes, but {} points of {} bytes "
                "need {} (corrupt file, or the header does not match the data)",
                uncompressedSize, header.points, header.stride, expectedSize));
        }
    }
    if (uncompressedSize > kMaxLzfExpansion * compressedSize + kLongestLzfReference) {
        throw Error(
            fmt::format("the PCD binary_compressed data claims to unpack {} compressed bytes to "
                        "{}, more than LZF can (corrupt file)",
                        compressedSize, uncompressedSize));
    }
    const auto unpacked = std::make_unique_for_overwrite<std::byte[]>(uncompressedSize);
    const unsigned int unpackedSize = lzf_decompress(
        body.data() + kLzfSizeHeaderBytes, compressedSize, unpacked.get(), uncompressedSize);
    if (unpackedSize == 0) {
        throw Error("the PCD binary_compressed data is corrupt (LZF decompression failed)");
    }
    if (unpackedSize != uncompressedSize) {
        throw Error(fmt::format(
            "the PCD binary_compressed data is corrupt: it unpacks to {} bytes instead of {}",
            unpackedSize, uncompressedSize));
    }
    readBinaryPoints({unpacked.get(), uncompressedSize}, header, true, paddingStored, sink,
                     context);
}

std::string describe(const PcdHeader& header) {
    std::string detail = "PCD";
    if (!header.version.empty()) {
        detail += " " + header.version;
    }
    detail += fmt::format(" {}, ", kDataKindNames[static_cast<int>(header.dataKind)]);
    if (header.height > 1) {
        return detail + fmt::format("organised {}x{}", header.width, header.height);
    }
    return detail + "unorganised";
}

}  // namespace

PointCloud readPcd(std::span<const std::byte> file, ReadContext& context) {
    const std::string_view text(reinterpret_cast<const char*>(file.data()), file.size());
    const PcdHeader header = parseHeader(text);
    context.formatDetail = describe(header);
    const FieldLayout layout = selectFields(header, context.warnings);
    const std::span<const std::byte> body = file.subspan(header.bodyOffset);

    // Never reserve more than the data could hold: a lying header must not allocate gigabytes.
    // An ascii value takes at least 2 bytes (a digit and a separator); binary sizes are checked
    // against the data before any point is read.
    std::uint64_t expectedPoints = header.points;
    if (header.dataKind == PcdDataKind::Ascii) {
        expectedPoints = std::min(expectedPoints, body.size() / (2 * header.valuesPerPoint) + 1);
    } else if (header.dataKind == PcdDataKind::Binary) {
        expectedPoints = std::min(expectedPoints, body.size() / header.stride);
    } else {
        expectedPoints =
            std::min(expectedPoints, kMaxLzfExpansion * body.size() / header.stride + 1);
    }
    PointSink sink(header, layout, static_cast<std::size_t>(expectedPoints),
                   context.keepFilePrecision);
    switch (header.dataKind) {
        case PcdDataKind::Ascii:
            readAscii(text.substr(header.bodyOffset), header, layout, sink, context);
            break;
        case PcdDataKind::Binary:
            readBinary(body, header, sink, context);
            break;
        case PcdDataKind::BinaryCompressed:
            readBinaryCompressed(body, header, sink, context);
            break;
    }
    context.reportProgress(header.points, header.points);
    PointCloud cloud = sink.finish(context.warnings);
    cloud.doubleCoordinates = std::any_of(
        layout.position.begin(), layout.position.end(),
        [&](std::size_t field) { return header.fields[field].type == PcdType::Float64; });
    context.sensor = SensorPose{header.viewpoint, header.viewpointGiven
                                                      ? "the PCD VIEWPOINT"
                                                      : "the PCD default VIEWPOINT (none given)"};
    if (header.height > 1) {
        context.grid = {static_cast<int>(header.width), static_cast<int>(header.height),
                        sink.takeCellOfPoint()};
    }
    return cloud;
}

}  // namespace subscan
