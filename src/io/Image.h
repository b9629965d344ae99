#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace subscan {

/// 8-bit image, rows top first, `channels` bytes per pixel.
struct Image8 {
    int width = 0;
    int height = 0;
    int channels = 4;
    std::vector<std::uint8_t> pixels;
};

/// Float image, rows top first, `channels` floats per pixel.
struct ImageF {
    int width = 0;
    int height = 0;
    int channels = 1;
    std::vector<float> values;
};

/// PNG (1-4 channels), written atomically. Throws subscan::Error naming the path.
void writePng(const std::filesystem::path& path, const Image8& image);
Image8 readPng(const std::filesystem::path& path);

/// The pictures writePicture() can write, chosen by the file's extension (any case): ".png",
/// ".jpg", ".jpeg". Throws subscan::Error naming the path and listing them for any other.
void checkPictureExtension(const std::filesystem::path& path);

/// PNG, or JPEG at quality 95 (alpha dropped: the pictures are opaque), by the extension;
/// written atomically. Throws subscan::Error as checkPictureExtension() and the writers do.
void writePicture(const std::filesystem::path& path, const Image8& image);

/// PFM, the portable float map: 1 ("Pf") or 3 ("PF") channels, little-endian, rows stored
/// bottom to top as the format specifies (the image in memory stays top first). Atomic write.
void writePfm(const std::filesystem::path& path, const ImageF& image);
ImageF readPfm(const std::filesystem::path& path);

}  // namespace subscan
