#include "io/Image.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

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

enum class PictureFormat { Png, Jpeg };

/// The format `path`'s extension names, or nullopt.
std::optional<PictureFormat> pictureFormat(const std::filesystem::path& path) {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (extension == ".png") {
        return PictureFormat::Png;
    }
    if (extension == ".jpg" || extension == ".jpeg") {
        return PictureFormat::Jpeg;
    }
    return std::nullopt;
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

void checkPictureExtension(const std::filesystem::path& path) {
    if (!pictureFormat(path)) {
        throw Error(fmt::format(
            "{}: pictures are written as .png or .jpg/.jpeg (the extension picks the format); "
            "the linear radiance is radiance.pfm of --export-buffers",
            path.string()));
    }
}

void writePicture(const std::filesystem::path& path, const Image8& image) {
    checkPictureExtension(path);
    if (*pictureFormat(path) == PictureFormat::Png) {
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
    if ((image.channels != 1 && image.channels != 3) ||
        image.values.size() != static_cast<std::size_t>(image.width) *
                                   static_cast<std::size_t>(image.height) *
                                   static_cast<std::size_t>(image.channels)) {
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
