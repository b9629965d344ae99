#include "io/Image.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb/stb_image_write.h>
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_PNG
#include <stb/stb_image.h>

#include "core/Error.h"
#include "io/AtomicFile.h"
#include "io/ByteOrder.h"
#include "io/MappedFile.h"
#include "io/TextParsing.h"
#include "io/WriterSupport.h"

namespace subscan {

namespace {

void checkSize(const std::filesystem::path& path, const Image8& image) {
    if (image.channels < 1 || image.channels > 4 ||
        image.pixels.size() != static_cast<std::size_t>(image.width) *
                                   static_cast<std::size_t>(image.height) *
                                   static_cast<std::size_t>(image.channels)) {
        throw Error(fmt::format("{}: the image to write has an inconsistent size", path.string()));
    }
}

/// stb's write callback: appends to the std::string `context`.
void appendTo(void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data),
                                               static_cast<std::size_t>(size));
}

struct PictureExtension {
    std::string_view extension;  // lowercase
    PictureFormat format;
};

constexpr std::array<PictureExtension, 5> kPictureExtensions{{
    {".png", PictureFormat::Png},
    {".jpg", PictureFormat::Jpeg},
    {".jpeg", PictureFormat::Jpeg},
    {".pfm", PictureFormat::Pfm},
    {".exr", PictureFormat::Exr},
}};

std::optional<PictureFormat> formatOfExtension(const std::filesystem::path& path) {
    const std::string extension = asciiLowercase(path.extension().string());
    for (const PictureExtension& candidate : kPictureExtensions) {
        if (candidate.extension == extension) {
            return candidate.format;
        }
    }
    return std::nullopt;
}

/// Whether the image holds width x height x channels values.
bool hasConsistentSize(const ImageF& image) {
    return image.values.size() == static_cast<std::size_t>(image.width) *
                                      static_cast<std::size_t>(image.height) *
                                      static_cast<std::size_t>(image.channels);
}

/// OpenEXR attribute: name, type name (both NUL-terminated), int32 size, value.
void appendExrAttribute(std::string& out, std::string_view name, std::string_view type,
                        std::string_view value) {
    out.append(name);
    out.push_back('\0');
    out.append(type);
    out.push_back('\0');
    appendLittleEndian(out, static_cast<std::int32_t>(value.size()));
    out.append(value);
}

template <class... Values>
std::string exrValue(Values... values) {
    std::string bytes;
    (appendLittleEndian(bytes, values), ...);
    return bytes;
}

}  // namespace

void writePng(const std::filesystem::path& path, const Image8& image) {
    checkSize(path, image);
    std::string encoded;
    if (stbi_write_png_to_func(appendTo, &encoded, image.width, image.height, image.channels,
                               image.pixels.data(), image.width * image.channels) == 0) {
        throw Error(fmt::format("{}: PNG encoding failed", path.string()));
    }
    writeFileAtomically(path, encoded);
}

PictureFormat pictureFormat(const std::filesystem::path& path) {
    if (const std::optional<PictureFormat> format = formatOfExtension(path)) {
        return *format;
    }
    throw Error(fmt::format(
        "{}: pictures are written as .png or .jpg/.jpeg (sRGB) or as .pfm or .exr (linear "
        "radiance, 32-bit float); the extension picks the format",
        path.string()));
}

bool holdsLinearRadiance(PictureFormat format) {
    return format == PictureFormat::Pfm || format == PictureFormat::Exr;
}

void writePicture(const std::filesystem::path& path, const Image8& image) {
    const PictureFormat format = pictureFormat(path);
    if (holdsLinearRadiance(format)) {
        throw Error(
            fmt::format("{}: a .pfm or .exr picture holds linear radiance, not 8-bit "
                        "colour",
                        path.string()));
    }
    if (format == PictureFormat::Png) {
        writePng(path, image);
        return;
    }
    checkSize(path, image);
    std::string encoded;
    constexpr int kJpegQuality = 95;  // no visible blocks on smooth shading, 3-4x smaller than PNG
    if (stbi_write_jpg_to_func(appendTo, &encoded, image.width, image.height, image.channels,
                               image.pixels.data(), kJpegQuality) == 0) {
        throw Error(fmt::format("{}: JPEG encoding failed", path.string()));
    }
    writeFileAtomically(path, encoded);
}

void writeLinearPicture(const std::filesystem::path& path, const ImageF& image) {
    switch (pictureFormat(path)) {
        case PictureFormat::Pfm:
            writePfm(path, image);
            return;
        case PictureFormat::Exr:
            writeExr(path, image);
            return;
        case PictureFormat::Png:
        case PictureFormat::Jpeg:
            break;
    }
    throw Error(fmt::format("{}: a .png or .jpg picture holds 8-bit sRGB, not linear radiance",
                            path.string()));
}

void writeExr(const std::filesystem::path& path, const ImageF& image) {
    if (image.channels != 3 || image.width <= 0 || image.height <= 0 || !hasConsistentSize(image)) {
        throw Error(
            fmt::format("{}: EXR pictures hold 3 channels of a consistent size", path.string()));
    }
    // The channel list names the channels in alphabetical order, and each scanline holds them
    // in that order: B, G, R, i.e. our channels 2, 1, 0.
    constexpr std::array<std::pair<char, std::size_t>, 3> kChannels{{{'B', 2}, {'G', 1}, {'R', 0}}};
    constexpr std::int32_t kFloatPixels = 2;  // UINT 0, HALF 1, FLOAT 2
    std::string channels;
    for (const auto& [name, index] : kChannels) {
        channels.push_back(name);
        channels.push_back('\0');
        appendLittleEndian(channels, kFloatPixels);
        channels.append(4, '\0');                       // pLinear, then 3 reserved bytes
        appendLittleEndian(channels, std::int32_t{1});  // x sampling
        appendLittleEndian(channels, std::int32_t{1});  // y sampling
    }
    channels.push_back('\0');
    const std::int32_t xMax = image.width - 1;
    const std::int32_t yMax = image.height - 1;
    const std::string window = exrValue(std::int32_t{0}, std::int32_t{0}, xMax, yMax);

    std::string out;
    appendLittleEndian(out, std::uint32_t{20000630});  // the magic number: 76 2f 31 01
    appendLittleEndian(out, std::uint32_t{2});         // version 2, single-part scanline
    appendExrAttribute(out, "channels", "chlist", channels);
    appendExrAttribute(out, "compression", "compression", std::string(1, '\0'));  // NO_COMPRESSION
    appendExrAttribute(out, "dataWindow", "box2i", window);
    appendExrAttribute(out, "displayWindow", "box2i", window);
    appendExrAttribute(out, "lineOrder", "lineOrder", std::string(1, '\0'));  // INCREASING_Y
    appendExrAttribute(out, "pixelAspectRatio", "float", exrValue(1.0f));
    appendExrAttribute(out, "screenWindowCenter", "v2f", exrValue(0.0f, 0.0f));
    appendExrAttribute(out, "screenWindowWidth", "float", exrValue(1.0f));
    out.push_back('\0');  // end of the header

    const auto width = static_cast<std::size_t>(image.width);
    const std::size_t lineBytes = width * kChannels.size() * sizeof(float);
    const std::size_t blockBytes = 2 * sizeof(std::int32_t) + lineBytes;
    const std::size_t firstBlock =
        out.size() + static_cast<std::size_t>(image.height) * sizeof(std::uint64_t);
    for (int y = 0; y < image.height; ++y) {
        appendLittleEndian(
            out, static_cast<std::uint64_t>(firstBlock + static_cast<std::size_t>(y) * blockBytes));
    }
    out.reserve(firstBlock + static_cast<std::size_t>(image.height) * blockBytes);
    for (int y = 0; y < image.height; ++y) {
        appendLittleEndian(out, static_cast<std::int32_t>(y));
        appendLittleEndian(out, static_cast<std::int32_t>(lineBytes));
        const float* row = image.values.data() + static_cast<std::size_t>(y) * width * 3;
        for (const auto& [name, index] : kChannels) {
            for (std::size_t x = 0; x < width; ++x) {
                appendLittleEndian(out, row[3 * x + index]);
            }
        }
    }
    writeFileAtomically(path, out);
}

Image8 readPng(const std::filesystem::path& path) {
    const MappedFile file(path);
    const auto bytes = file.bytes();
    int width = 0, height = 0, channels = 0;
    stbi_uc* pixels =
        stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()),
                              static_cast<int>(bytes.size()), &width, &height, &channels, 0);
    if (pixels == nullptr) {
        throw Error(
            fmt::format("{}: not a readable PNG ({})", path.string(), stbi_failure_reason()));
    }
    Image8 image{width, height, channels, {}};
    image.pixels.assign(pixels, pixels + static_cast<std::size_t>(width) *
                                             static_cast<std::size_t>(height) *
                                             static_cast<std::size_t>(channels));
    stbi_image_free(pixels);
    return image;
}

void writePfm(const std::filesystem::path& path, const ImageF& image) {
    if ((image.channels != 1 && image.channels != 3) || !hasConsistentSize(image)) {
        throw Error(
            fmt::format("{}: PFM holds 1 or 3 channels of a consistent size", path.string()));
    }
    writeFileAtomically(path, [&](std::ostream& stream) {
        // A negative scale marks little-endian data.
        stream << (image.channels == 3 ? "PF" : "Pf") << '\n'
               << image.width << ' ' << image.height << "\n-1.0\n";
        const std::size_t rowFloats =
            static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.channels);
        std::vector<float> row(rowFloats);
        for (int y = image.height - 1; y >= 0; --y) {
            const float* source = image.values.data() + static_cast<std::size_t>(y) * rowFloats;
            for (std::size_t i = 0; i < rowFloats; ++i) {
                row[i] = loadLittleEndian<float>(&source[i]);  // identity on little-endian hosts
            }
            stream.write(reinterpret_cast<const char*>(row.data()),
                         static_cast<std::streamsize>(rowFloats * sizeof(float)));
        }
    });
}

ImageF readPfm(const std::filesystem::path& path) {
    const MappedFile file(path);
    const auto bytes = file.bytes();
    const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    std::istringstream header{std::string(text.substr(0, std::min<std::size_t>(text.size(), 256)))};
    std::string magic;
    ImageF image;
    double scale = 0.0;
    header >> magic >> image.width >> image.height >> scale;
    if (!header || (magic != "Pf" && magic != "PF") || image.width <= 0 || image.height <= 0 ||
        scale == 0.0) {
        throw Error(fmt::format("{}: not a PFM image", path.string()));
    }
    header.get();  // the single whitespace after the scale
    image.channels = magic == "PF" ? 3 : 1;
    const std::size_t offset = static_cast<std::size_t>(header.tellg());
    const std::size_t rowFloats =
        static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.channels);
    const std::size_t count = rowFloats * static_cast<std::size_t>(image.height);
    if (bytes.size() < offset || (bytes.size() - offset) / sizeof(float) < count) {
        throw Error(fmt::format("{}: the PFM data is truncated", path.string()));
    }
    image.values.resize(count);
    const bool bigEndian = scale > 0.0;
    for (int y = 0; y < image.height; ++y) {
        const std::byte* row =
            bytes.data() + offset +
            static_cast<std::size_t>(image.height - 1 - y) * rowFloats * sizeof(float);
        for (std::size_t i = 0; i < rowFloats; ++i) {
            const std::byte* p = row + i * sizeof(float);
            image.values[static_cast<std::size_t>(y) * rowFloats + i] =
                bigEndian ? loadBigEndian<float>(p) : loadLittleEndian<float>(p);
        }
    }
    return image;
}

}  // namespace subscan
