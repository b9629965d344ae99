#include "io/RecordSourceSupport.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "core/Error.h"
#include "io/ByteOrder.h"
#include "io/LasWriter.h"

namespace subscan {

namespace {

// Fields of an extra-bytes descriptor (R15, table 24).
namespace descriptor_field {
constexpr std::size_t kDataType = 2;
constexpr std::size_t kOptions = 3;
constexpr std::size_t kName = 4;
constexpr std::size_t kNameSize = 32;
constexpr std::size_t kScale = 112;  // three doubles
constexpr std::size_t kOffset = 136;
constexpr std::size_t kDescription = 160;
constexpr std::size_t kDescriptionSize = 32;
}  // namespace descriptor_field

// Options bits that change what the stored values mean.
constexpr std::uint8_t kScaleBit = 1 << 3;
constexpr std::uint8_t kOffsetBit = 1 << 4;
constexpr std::uint8_t kUndocumented = 0;
constexpr std::uint8_t kFloatType = 9;
constexpr std::size_t kLargestUndocumented = 255;  // the options byte holds the size

/// Size of a data type 1-30: ten scalar types, then (deprecated) pairs and triples of them.
std::optional<std::size_t> dataTypeSize(std::uint8_t type) {
    static constexpr std::array<std::size_t, 10> kScalarSizes{1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
    if (type == kUndocumented || type > 30) {
        return std::nullopt;
    }
    const std::size_t index = (type - 1u) % 10u;
    const std::size_t elements = (type - 1u) / 10u + 1u;
    return kScalarSizes[index] * elements;
}

std::string_view fixedString(std::span<const std::byte> field) {
    const std::string_view text(reinterpret_cast<const char*>(field.data()), field.size());
    return text.substr(0, text.find('\0'));
}

void putFixedString(std::byte* out, std::string_view text, std::size_t size) {
    std::memcpy(out, text.data(), std::min(text.size(), size));
}

std::span<const std::byte> descriptorAt(std::span<const std::byte> descriptors, std::size_t i) {
    return descriptors.subspan(i * kExtraBytesDescriptorSize, kExtraBytesDescriptorSize);
}

std::uint8_t descriptorByte(std::span<const std::byte> bytes, std::size_t offset) {
    return std::to_integer<std::uint8_t>(bytes[offset]);
}

std::vector<std::byte> newDescriptor(std::uint8_t type, std::uint8_t options, std::string_view name,
                                     std::string_view description) {
    std::vector<std::byte> descriptor(kExtraBytesDescriptorSize, std::byte{0});
    descriptor[descriptor_field::kDataType] = static_cast<std::byte>(type);
    descriptor[descriptor_field::kOptions] = static_cast<std::byte>(options);
    putFixedString(descriptor.data() + descriptor_field::kName, name, descriptor_field::kNameSize);
    putFixedString(descriptor.data() + descriptor_field::kDescription, description,
                   descriptor_field::kDescriptionSize);
    return descriptor;
}

std::uint16_t clampedWord(double value, double largest) {
    if (!(value > 0.0)) {
        return 0;  // also NaN
    }
    return static_cast<std::uint16_t>(std::lround(std::min(value, largest)));
}

double coarsestStep(const Quantization& quantization) {
    return std::max({quantization.scale.x, quantization.scale.y, quantization.scale.z});
}

}  // namespace

std::size_t las14::standardSize(int pointFormat) {
    return pointFormat == 8 ? 38 : pointFormat == 7 ? 36 : 30;
}

void appendFloatDescriptor(std::vector<std::byte>& descriptors, std::string_view name,
                           std::string_view description) {
    const std::vector<std::byte> descriptor = newDescriptor(kFloatType, 0, name, description);
    descriptors.insert(descriptors.end(), descriptor.begin(), descriptor.end());
}

std::vector<std::byte> undocumentedDescriptors(std::size_t bytes) {
    std::vector<std::byte> descriptors;
    for (std::size_t first = 0; first < bytes; first += kLargestUndocumented) {
        const std::size_t size = std::min(kLargestUndocumented, bytes - first);
        const std::vector<std::byte> descriptor =
            newDescriptor(kUndocumented, static_cast<std::uint8_t>(size),
                          fmt::format("undocumented_{}", first), "undocumented extra bytes");
        descriptors.insert(descriptors.end(), descriptor.begin(), descriptor.end());
    }
    return descriptors;
}

std::optional<std::size_t> describedBytes(std::span<const std::byte> descriptors) {
    if (descriptors.size() % kExtraBytesDescriptorSize != 0) {
        return std::nullopt;
    }
    std::size_t total = 0;
    for (std::size_t i = 0; i < descriptors.size() / kExtraBytesDescriptorSize; ++i) {
        const std::span<const std::byte> descriptor = descriptorAt(descriptors, i);
        const std::uint8_t type = descriptorByte(descriptor, descriptor_field::kDataType);
        const std::uint8_t options = descriptorByte(descriptor, descriptor_field::kOptions);
        const std::optional<std::size_t> size = type == kUndocumented && options > 0
                                                    ? std::optional<std::size_t>(options)
                                                    : dataTypeSize(type);
        if (!size) {
            return std::nullopt;
        }
        total += *size;
    }
    return total;
}

bool sameExtraBytesFields(std::span<const std::byte> a, std::span<const std::byte> b) {
    if (a.size() != b.size()) {
        return false;
    }
    for (std::size_t i = 0; i < a.size() / kExtraBytesDescriptorSize; ++i) {
        const std::span<const std::byte> p = descriptorAt(a, i);
        const std::span<const std::byte> q = descriptorAt(b, i);
        const std::uint8_t type = descriptorByte(p, descriptor_field::kDataType);
        // The options of undocumented bytes are their size; of others, only the scale and
        // offset bits change what a value means.
        const std::uint8_t meaning = type == kUndocumented ? 0xFF : kScaleBit | kOffsetBit;
        const std::uint8_t options = descriptorByte(p, descriptor_field::kOptions) & meaning;
        const auto field = [](std::span<const std::byte> d, std::size_t offset, std::size_t size) {
            return d.subspan(offset, size);
        };
        const auto equal = [&](std::size_t offset, std::size_t size) {
            return std::ranges::equal(field(p, offset, size), field(q, offset, size));
        };
        if (type != descriptorByte(q, descriptor_field::kDataType) ||
            options != (descriptorByte(q, descriptor_field::kOptions) & meaning) ||
            fixedString(field(p, descriptor_field::kName, descriptor_field::kNameSize)) !=
                fixedString(field(q, descriptor_field::kName, descriptor_field::kNameSize)) ||
            ((options & kScaleBit) != 0 && !equal(descriptor_field::kScale, 24)) ||
            ((options & kOffsetBit) != 0 && !equal(descriptor_field::kOffset, 24))) {
            return false;
        }
    }
    return true;
}

std::string extraBytesFieldNames(std::span<const std::byte> descriptors) {
    std::vector<std::string_view> names;
    for (std::size_t i = 0; i < descriptors.size() / kExtraBytesDescriptorSize; ++i) {
        names.push_back(
            fixedString(descriptorAt(descriptors, i)
                            .subspan(descriptor_field::kName, descriptor_field::kNameSize)));
    }
    return names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "));
}

std::uint16_t colorWordFromByte(double value) {
    return static_cast<std::uint16_t>(clampedWord(value, 255.0) * 257u);
}

std::uint16_t colorWordFromWord(double value) {
    return clampedWord(value, 65535.0);
}

std::uint16_t colorWordFromUnit(double value) {
    return clampedWord(value * 65535.0, 65535.0);
}

std::uint16_t intensityWord(double value) {
    return clampedWord(value, 65535.0);
}

bool fitsIntensityWord(double value) {
    return value >= 0.0 && value <= 65535.0 && value == std::floor(value);
}

bool fitIntensityWords(std::span<const float> intensities) {
    return std::all_of(intensities.begin(), intensities.end(),
                       [](float value) { return fitsIntensityWord(value); });
}

std::string intensitiesNotKept(const std::string& name) {
    return fmt::format(
        "{}: its intensities are not all whole numbers within 0..65535, which LAS holds: they "
        "are written rounded and clamped to that range",
        name);
}

ConvertedRecordWriter::ConvertedRecordWriter(bool color, bool normals, const Bounds& bounds)
    : normals_(normals) {
    format_.pointFormat = color ? 7 : 6;
    if (normals) {
        format_.extraBytes = 3 * sizeof(float);
        appendFloatDescriptor(format_.extraBytesDescriptors, "NormalX", "X component of normal");
        appendFloatDescriptor(format_.extraBytesDescriptors, "NormalY", "Y component of normal");
        appendFloatDescriptor(format_.extraBytesDescriptors, "NormalZ", "Z component of normal");
    }
    const LasScaling scaling = chooseLasScaling(bounds);
    quantization_.scale = scaling.scale;
    quantization_.offset = scaling.offset;
}

std::array<std::int32_t, 3> ConvertedRecordWriter::stored(const glm::dvec3& position) const {
    std::array<std::int32_t, 3> values{};
    for (int axis = 0; axis < 3; ++axis) {
        const double steps =
            std::round((position[axis] - quantization_.offset[axis]) / quantization_.scale[axis]);
        if (!(std::abs(steps) <= std::numeric_limits<std::int32_t>::max())) {
            throw Error(fmt::format(
                "the {} coordinate {:.17g} lies outside the bounds its quantization was chosen "
                "for",
                "xyz"[axis], position[axis]));
        }
        values[axis] = static_cast<std::int32_t>(steps);
    }
    return values;
}

Bounds ConvertedRecordWriter::storedBounds(const Bounds& bounds) const {
    Bounds result;
    if (!bounds.empty()) {
        // Rounding is monotonic, so the extreme coordinates give the extreme stored values.
        for (const glm::dvec3& corner : {bounds.min, bounds.max}) {
            const std::array<std::int32_t, 3> values = stored(corner);
            result.add(glm::dvec3(values[0], values[1], values[2]) * quantization_.scale +
                       quantization_.offset);
        }
    }
    return result;
}

void ConvertedRecordWriter::append(std::vector<std::byte>& records,
                                   const ConvertedPoint& point) const {
    const std::size_t start = records.size();
    records.resize(start + format_.recordLength(), std::byte{0});
    std::byte* record = records.data() + start;
    const std::array<std::int32_t, 3> values = stored(point.position);
    std::memcpy(record, values.data(), sizeof(values));
    std::memcpy(record + las14::kIntensity, &point.intensity, sizeof(point.intensity));
    record[las14::kReturns] = std::byte{las14::kFirstOfOneReturn};
    record[las14::kClassification] = static_cast<std::byte>(point.classification);
    if (format_.pointFormat == 7) {
        std::memcpy(record + las14::kRgb, point.rgb.data(), sizeof(point.rgb));
    }
    if (normals_) {
        std::memcpy(record + las14::standardSize(format_.pointFormat), &point.normal,
                    sizeof(point.normal));
    }
}

std::string facesNotKept(const std::string& name, std::uint64_t faces) {
    return fmt::format("{}: its faces ({}) are not kept: point records hold points only", name,
                       faces);
}

void ConvertedRecordSource::startRecords(std::string name, std::uint64_t pointCount, bool color,
                                         bool normals, const Bounds& bounds, double coordinateStep,
                                         std::vector<std::string> warnings) {
    try {
        writer_.emplace(color, normals, bounds);
    } catch (const Error& error) {
        throwNamed(name, error);
    }
    bounds_ = bounds;
    keptStep_ = coordinateStep > 0.0
                    ? std::max(coordinateStep, coarsestStep(writer_->quantization()))
                    : 0.0;
    info_.name = std::move(name);
    info_.pointCount = pointCount;
    info_.format = writer_->format();
    info_.warnings = std::move(warnings);
    setQuantization(writer_->quantization());
}

void ConvertedRecordSource::useQuantization(const Quantization& quantization) {
    setQuantization(quantization);
    const double step = coarsestStep(quantization);
    // Scales are powers of ten held in doubles: one equal to the kept step may differ from it in
    // the last place.
    if (keptStep_ > 0.0 && step > keptStep_ * (1.0 + 1e-9)) {
        info_.warnings.push_back(fmt::format(
            "{}: its coordinates are written to steps of {:g}, but the grid it shares with the "
            "other inputs (the finest their combined extent allows in 32-bit integers) has steps "
            "of {:g}: they are rounded to it",
            info_.name, keptStep_, step));
    }
}

void ConvertedRecordSource::setQuantization(const Quantization& quantization) {
    writer_->setQuantization(quantization);
    info_.quantization = quantization;
    const Bounds stored = writer_->storedBounds(bounds_);
    info_.min = stored.min;
    info_.max = stored.max;
}

void throwNamed(const std::string& name, const Error& error) {
    throw Error(fmt::format("{}: {}", name, error.what()));
}

}  // namespace subscan
