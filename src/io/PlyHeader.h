#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io/ByteOrder.h"

// The PLY header (Turk's format description): what the reader of whole files and the reader of
// binary vertices in pieces share.
namespace subscan {

enum class PlyEncoding { Ascii, BinaryLittleEndian, BinaryBigEndian };
enum class PlyType : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::Float32;  // the item type for lists
    bool isList = false;
    PlyType countType = PlyType::UInt8;
};

struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> properties;

    /// Byte size of one item when it has no lists, else nullopt.
    std::optional<std::size_t> fixedStride() const;
    std::optional<std::size_t> find(std::string_view propertyName) const {
        for (std::size_t i = 0; i < properties.size(); ++i) {
            if (properties[i].name == propertyName) {
                return i;
            }
        }
        return std::nullopt;
    }
};

struct PlyHeader {
    PlyEncoding encoding = PlyEncoding::Ascii;
    std::string version;
    std::vector<PlyElement> elements;
    std::size_t bodyOffset = 0;
    std::size_t headerLines = 0;  // up to and including end_header, to number the body's lines
};

std::size_t plySizeOf(PlyType type);
bool isPlyInteger(PlyType type);

/// One binary value of `type` at `p`, in either byte order.
inline double loadPlyValue(PlyType type, bool bigEndian, const std::byte* p) {
    const auto load = [&]<class T>(T) -> double {
        return static_cast<double>(bigEndian ? loadBigEndian<T>(p) : loadLittleEndian<T>(p));
    };
    switch (type) {
        case PlyType::Int8:
            return load(std::int8_t{});
        case PlyType::UInt8:
            return load(std::uint8_t{});
        case PlyType::Int16:
            return load(std::int16_t{});
        case PlyType::UInt16:
            return load(std::uint16_t{});
        case PlyType::Int32:
            return load(std::int32_t{});
        case PlyType::UInt32:
            return load(std::uint32_t{});
        case PlyType::Float32:
            return load(float{});
        case PlyType::Float64:
            return load(double{});
    }
    return 0.0;
}

/// Reads the header up to and including the `end_header` line (`file` may be only the start of
/// the file, if it holds that line). Throws subscan::Error naming the line that is wrong.
PlyHeader parsePlyHeader(std::string_view file);

/// Which vertex properties hold what we keep; indices into PlyElement::properties.
struct PlyVertexLayout {
    std::array<std::size_t, 3> position{};
    std::optional<std::array<std::size_t, 3>> color;
    std::optional<std::size_t> alpha;
    std::optional<std::array<std::size_t, 3>> normal;
    std::optional<std::size_t> intensity;

    /// The colour properties read: red, green and blue, then alpha if there is one.
    std::vector<std::size_t> colorChannels() const {
        std::vector<std::size_t> channels;
        if (color) {
            channels.assign(color->begin(), color->end());
            if (alpha) {
                channels.push_back(*alpha);
            }
        }
        return channels;
    }
};

/// x, y and z (required, else subscan::Error), red/green/blue[/alpha] or diffuse_*, nx/ny/nz,
/// intensity or scalar_intensity; a list where a value belongs is an error.
PlyVertexLayout findPlyVertexLayout(const PlyElement& vertex);

/// How a colour property's values map to 0..255: as they are, from 0..65535 or from 0..1.
enum class PlyColorScale { Byte, Word, Unit };

/// Writers store colour in wider types than its values need: PDAL writes LAS colour (often
/// 8-bit values) as ushort, and some write float colour as 0..255. So, as the LAS, PCD and text
/// readers judge, 16-bit channels are 0..255 and float ones 0..1 unless some colour value of the
/// whole file is larger: above 255 in a 16-bit channel, above 1 in a float one.
bool isLargePlyColorValue(PlyType type, double value);
/// `largeValues`: whether isLargePlyColorValue held for any colour value of the file.
PlyColorScale plyColorScale(PlyType type, bool largeValues);

}  // namespace subscan
