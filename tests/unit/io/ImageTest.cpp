#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

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
    for (const char* name : {"e.bmp", "f.tiff", "noextension"}) {
        try {
            writePicture(dir / name, image);
            ADD_FAILURE() << name << " written";
        } catch (const Error& error) {
            EXPECT_EQ(std::string(error.what()),
                      (dir / name).string() +
                          ": pictures are written as .png or .jpg/.jpeg (sRGB) or as .pfm or "
                          ".exr (linear radiance, 32-bit float); the extension picks the format");
        }
        EXPECT_FALSE(std::filesystem::exists(dir / name));
    }
    // The float formats take the linear radiance, and the 8-bit ones only 8-bit colour.
    for (const char* name : {"g.pfm", "h.EXR"}) {
        EXPECT_THROW(writePicture(dir / name, image), Error) << name;
        EXPECT_FALSE(std::filesystem::exists(dir / name));
    }
    const ImageF radiance{2, 1, 3, {0.5f, 1.5f, 2.5f, 0.0f, 0.25f, 100.0f}};
    EXPECT_THROW(writeLinearPicture(dir / "i.png", radiance), Error);
    EXPECT_FALSE(std::filesystem::exists(dir / "i.png"));
    writeLinearPicture(dir / "j.PFM", radiance);
    EXPECT_EQ(readPfm(dir / "j.PFM").values, radiance.values);
    writeLinearPicture(dir / "k.exr", radiance);
    EXPECT_EQ(test::readExr(dir / "k.exr").image.values, radiance.values);
}

TEST(ImageTest, ExrFollowsTheOpenExrFileLayout) {
    const test::TempDir dir;
    // 3 x 2 pixels, every value distinct (and R, G, B told apart by their tens), with the
    // extremes float radiance may hold.
    ImageF image{3, 2, 3, {}};
    for (int i = 0; i < 18; ++i) {
        image.values.push_back(static_cast<float>(i % 3) * 10.0f + static_cast<float>(i / 3));
    }
    image.values[4] = 1e30f;
    image.values[17] = std::numeric_limits<float>::infinity();
    writeExr(dir / "a.exr", image);
    const std::string bytes = test::fileBytes(dir / "a.exr");
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x76\x2f\x31\x01\x02\x00\x00\x00", 8));

    const test::ExrFile file = test::readExr(dir / "a.exr");
    EXPECT_EQ(file.magic, 20000630u);
    EXPECT_EQ(file.version, 2u);  // single-part scanline, no flags
    // The attributes a reader requires, each with its type and value, by hand.
    const auto le32 = [](std::initializer_list<std::int32_t> values) {
        std::string out;
        for (const std::int32_t value : values) {
            test::appendBytes(out, value);
        }
        return out;
    };
    const auto f32 = [](std::initializer_list<float> values) {
        std::string out;
        for (const float value : values) {
            test::appendBytes(out, value);
        }
        return out;
    };
    std::string channels;
    for (const char name : {'B', 'G', 'R'}) {  // sorted by name, as the format requires
        channels += std::string(1, name) + '\0' + le32({2}) + std::string(4, '\0') + le32({1, 1});
    }
    channels += '\0';
    const std::vector<test::ExrAttribute> expected{
        {"channels", "chlist", channels},
        {"compression", "compression", std::string(1, '\0')},
        {"dataWindow", "box2i", le32({0, 0, 2, 1})},
        {"displayWindow", "box2i", le32({0, 0, 2, 1})},
        {"lineOrder", "lineOrder", std::string(1, '\0')},
        {"pixelAspectRatio", "float", f32({1.0f})},
        {"screenWindowCenter", "v2f", f32({0.0f, 0.0f})},
        {"screenWindowWidth", "float", f32({1.0f})},
    };
    ASSERT_EQ(file.attributes.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(file.attributes[i].name, expected[i].name);
        EXPECT_EQ(file.attributes[i].type, expected[i].type) << expected[i].name;
        EXPECT_EQ(file.attributes[i].value, expected[i].value) << expected[i].name;
    }
    // Two blocks of one scanline each: y, byte count, then the row's B, G and R values; the
    // offsets point at them, right after the table, and the file ends with the last.
    ASSERT_EQ(file.offsets.size(), 2u);
    constexpr std::size_t kBlock = 4 + 4 + 3 * 3 * 4;
    EXPECT_EQ(file.offsets[1], file.offsets[0] + kBlock);
    EXPECT_EQ(file.offsets[1] + kBlock, bytes.size());
    EXPECT_EQ(file.blockRows, (std::vector<std::int32_t>{0, 1}));
    float firstBlue = 0.0f;
    std::memcpy(&firstBlue, bytes.data() + file.offsets[0] + 8, sizeof firstBlue);
    EXPECT_EQ(firstBlue, image.values[2]);
    EXPECT_EQ(file.image.width, 3);
    EXPECT_EQ(file.image.height, 2);
    EXPECT_EQ(file.image.values, image.values);

    EXPECT_THROW(writeExr(dir / "b.exr", ImageF{2, 2, 1, std::vector<float>(4)}), Error);
    EXPECT_FALSE(std::filesystem::exists(dir / "b.exr"));
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
