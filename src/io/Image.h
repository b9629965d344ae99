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

/// The pictures `subscan render -o` writes, chosen by the file's extension (any case): 8-bit
/// sRGB ".png" and ".jpg"/".jpeg", and the linear radiance as 32-bit floats in ".pfm" and ".exr".
enum class PictureFormat { Png, Jpeg, Pfm, Exr };

/// The format `path`'s extension names. Throws subscan::Error naming the path and listing the
/// supported extensions for any other.
PictureFormat pictureFormat(const std::filesystem::path& path);
/// PFM and EXR: the picture is linear radiance (writeLinearPicture), not 8-bit sRGB.
bool holdsLinearRadiance(PictureFormat format);
/// PNG, or JPEG at quality 95 (alpha dropped: the pictures are opaque), by the extension;
/// written atomically. Throws subscan::Error as pictureFormat() and the writers do, and
/// for the linear formats (they take writeLinearPicture's float image).
void writePicture(const std::filesystem::path& path, const Image8& image);

/// Linear RGB (3 channels) as PFM or EXR (writePfm, writeExr) by the extension; written
/// atomically. Throws subscan::Error for the 8-bit formats and as the writers do.
void writeLinearPicture(const std::filesystem::path& path, const ImageF& image);

/// OpenEXR 2 (the public file-layout description: single-part scanline file), 3 channels of
/// 32-bit FLOAT named B, G, R (the channel list sorted by name, as the format requires),
/// NO_COMPRESSION, one scanline per block, INCREASING_Y (row 0 at the top, as in memory), data
/// and display window the whole image, pixel aspect ratio 1. Written atomically; throws
/// subscan::Error naming the path for an image that is not 3 channels of a consistent size.
void writeExr(const std::filesystem::path& path, const ImageF& image);

/// PFM, the portable float map: 1 ("Pf") or 3 ("PF") channels, little-endian, rows stored
/// bottom to top as the format specifies (the image in memory stays top first). Atomic write.
void writePfm(const std::filesystem::path& path, const ImageF& image);
ImageF readPfm(const std::filesystem::path& path);

}  // namespace subscan
