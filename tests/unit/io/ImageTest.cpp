#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "io/Image.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

TEST(ImageTest, PfmStoresRowsBottomUpAndRoundTrips) {
    const test::TempDir dir;
    const ImageF image{3, 2, 1, {1, 2, 3, 4, 5, std::numeric_limits<float>::infinity()}};
    writePfm(dir / "d.pfm", image);
    // The first stored row is the image's bottom row (4, 5, inf), as the format requires.
    std::ifstream stream(dir / "d.pfm", std::ios::binary);
    std::string header(std::istreambuf_iterator<char>(stream), {});
    ASSERT_EQ(header.substr(0, 12), "Pf\n3 2\n-1.0\n");
    float first = 0;
    std::memcpy(&first, header.data() + 12, sizeof(float));
    EXPECT_EQ(first, 4.0f);
    const ImageF back = readPfm(dir / "d.pfm");
    EXPECT_EQ(back.width, 3);
    EXPECT_EQ(back.height, 2);
    EXPECT_EQ(back.values, image.values);
}

TEST(ImageTest, PngRoundTrips) {
    const test::TempDir dir;
    Image8 image{5, 3, 4, {}};
    for (int i = 0; i < 5 * 3 * 4; ++i) {
        image.pixels.push_back(static_cast<std::uint8_t>(i * 17));
    }
    writePng(dir / "i.png", image);
    const Image8 back = readPng(dir / "i.png");
    EXPECT_EQ(back.width, 5);
    EXPECT_EQ(back.height, 3);
    EXPECT_EQ(back.channels, 4);
    EXPECT_EQ(back.pixels, image.pixels);
}

TEST(ImageTest, PicturesFollowTheirExtension) {
    const test::TempDir dir;
    Image8 image{6, 4, 4, std::vector<std::uint8_t>(6 * 4 * 4, 200)};
    writePicture(dir / "a.PNG", image);
    EXPECT_EQ(test::fileBytes(dir / "a.PNG").substr(0, 8), "\x89PNG\r\n\x1a\n");
    for (const char* name : {"b.jpg", "c.JPEG"}) {
        writePicture(dir / name, image);
        const std::string jpeg = test::fileBytes(dir / name);
        ASSERT_GT(jpeg.size(), 100u) << name;
        EXPECT_EQ(jpeg.substr(0, 3), "\xFF\xD8\xFF") << name;  // start of image
        // The baseline frame header (SOF0) holds the height, then the width, big-endian.
        const std::size_t frame = jpeg.find("\xFF\xC0");
        ASSERT_NE(frame, std::string::npos) << name;
        EXPECT_EQ(static_cast<unsigned char>(jpeg[frame + 6]), 4) << name;
        EXPECT_EQ(static_cast<unsigned char>(jpeg[frame + 8]), 6) << name;
    }
    for (const char* name : {"d.exr", "e.bmp", "noextension"}) {
        try {
            writePicture(dir / name, image);
            ADD_FAILURE() << name << " written";
        } catch (const Error& error) {
            EXPECT_EQ(std::string(error.what()),
                      (dir / name).string() +
                          ": pictures are written as .png or .jpg/.jpeg (the extension picks the "
                          "format); the linear radiance is radiance.pfm of --export-buffers");
        }
        EXPECT_FALSE(std::filesystem::exists(dir / name));
    }
}

TEST(ImageTest, AFailedWriteKeepsTheOldFile) {
    // Writers refuse an image they cannot encode, or fail to replace what is there, without
    // touching the file already at the path or leaving a temporary beside it.
    const test::TempDir dir;
    const auto png = dir.write("old.png", "old png");
    const auto pfm = dir.write("old.pfm", "old pfm");
    EXPECT_THROW(writePng(png, Image8{4, 4, 4, std::vector<std::uint8_t>(10)}), Error);
    EXPECT_THROW(writePfm(pfm, ImageF{2, 2, 2, std::vector<float>(8)}), Error);  // 2 channels
    EXPECT_EQ(test::fileBytes(png), "old png");
    EXPECT_EQ(test::fileBytes(pfm), "old pfm");
    // A folder where the picture should go: encoded, then the rename fails.
    const auto folder = dir / "busy.png";
    std::filesystem::create_directory(folder);
    dir.write("busy.png/inside", "kept");
    EXPECT_THROW(writePng(folder, Image8{1, 1, 4, {1, 2, 3, 4}}), Error);
    EXPECT_EQ(test::fileBytes(folder / "inside"), "kept");
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 3);
}

}  // namespace
}  // namespace subscan
