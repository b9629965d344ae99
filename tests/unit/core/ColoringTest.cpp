// What --color shows: each colouring against its rule, Auto's choice, and the errors.
#include <cstdint>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Coloring.h"
#include "core/Error.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

/// 1,000 points along a line rising in y (0..999) and falling in z, with intensities 0..999
/// and, if asked, colours.
PointCloud line(bool colors) {
    PointCloudBuilder builder({.color = colors, .intensity = true}, 1000);
    for (int i = 0; i < 1000; ++i) {
        PointRecord record;
        record.position = {0.0, i, 999 - i};
        record.intensity = static_cast<float>(i);
        record.color = {10, 20, 30, 128};
        builder.add(record);
    }
    std::vector<std::string> warnings;
    return builder.finish(warnings);
}

TEST(ColoringTest, NamesRoundTripAndABadOneListsTheChoices) {
    for (const Coloring coloring :
         {Coloring::Auto, Coloring::Rgb, Coloring::Intensity, Coloring::Height, Coloring::Uniform,
          Coloring::Classification}) {
        EXPECT_EQ(parseColoring(toString(coloring)), coloring);
    }
    try {
        parseColoring("rainbow");
        FAIL() << "accepted 'rainbow'";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(),
                    HasSubstr("auto, rgb, intensity, height, uniform, classification"));
    }
}

TEST(ColoringTest, RgbIsTheScansOwnAndUniformOneGrey) {
    const PointCloud cloud = line(true);
    EXPECT_EQ(pointColors(cloud, Coloring::Rgb, UpAxis::Y), cloud.colors);
    for (const Rgba8& color : pointColors(cloud, Coloring::Uniform, UpAxis::Y)) {
        EXPECT_EQ(color, (Rgba8{200, 200, 200, 255}));
    }
}

TEST(ColoringTest, IntensityStretchesThe1stTo99thPercentileOverGrey) {
    const std::vector<Rgba8> colors = pointColors(line(false), Coloring::Intensity, UpAxis::Y);
    // Intensities 0..999: the 1st percentile is 10, the 99th 989; below and above clamp.
    EXPECT_EQ(colors[0], (Rgba8{40, 40, 40, 255}));
    EXPECT_EQ(colors[10], (Rgba8{40, 40, 40, 255}));
    EXPECT_EQ(colors[989], (Rgba8{255, 255, 255, 255}));
    EXPECT_EQ(colors[999], (Rgba8{255, 255, 255, 255}));
    // Halfway (499.5) is 40 + 215 / 2.
    EXPECT_NEAR(colors[499].r + colors[500].r, 2 * (40 + 107.5), 1.0);
}

TEST(ColoringTest, HeightRampsViridisAlongTheUpAxis) {
    const PointCloud cloud = line(false);
    const std::vector<Rgba8> yUp = pointColors(cloud, Coloring::Height, UpAxis::Y);
    // y rises with the index: the lowest point is viridis' first stop, the highest its last,
    // the middle its middle (33, 145, 140).
    EXPECT_EQ(yUp[0], (Rgba8{68, 1, 84, 255}));
    EXPECT_EQ(yUp[999], (Rgba8{253, 231, 37, 255}));
    EXPECT_NEAR(yUp[499].g, 145, 2);  // 499 of 10..989 is 0.4995 of the way
    // z falls with the index: with Z up the ramp runs the other way.
    const std::vector<Rgba8> zUp = pointColors(cloud, Coloring::Height, UpAxis::Z);
    EXPECT_EQ(zUp[0], yUp[999]);
    EXPECT_EQ(zUp[999], yUp[0]);
    // With -Y up (a depth camera's frame) the ramp runs against y.
    const std::vector<Rgba8> yDown = pointColors(cloud, Coloring::Height, UpAxis::NegativeY);
    EXPECT_EQ(yDown[0], yUp[999]);
    EXPECT_EQ(yDown[999], yUp[0]);
}

TEST(ColoringTest, AutoShowsColourElseHeightForZUpElseUniform) {
    EXPECT_EQ(pointColors(line(true), Coloring::Auto, UpAxis::Y), line(true).colors);
    EXPECT_EQ(pointColors(line(false), Coloring::Auto, UpAxis::Z),
              pointColors(line(false), Coloring::Height, UpAxis::Z));
    // Not the intensity: in object scans it is the scanner's confidence.
    EXPECT_EQ(pointColors(line(false), Coloring::Auto, UpAxis::Y),
              pointColors(line(false), Coloring::Uniform, UpAxis::Y));
}

TEST(ColoringTest, WhatTheScanLacksIsNamed) {
    EXPECT_THAT([] { pointColors(line(false), Coloring::Rgb, UpAxis::Y); },
                ::testing::ThrowsMessage<Error>(HasSubstr("the scan has no colours to show")));
    PointCloud noIntensity = line(true);
    noIntensity.intensities.clear();
    EXPECT_THAT([&] { pointColors(noIntensity, Coloring::Intensity, UpAxis::Y); },
                ::testing::ThrowsMessage<Error>(HasSubstr("the scan has no intensities")));
    EXPECT_THAT([] { pointColors(line(true), Coloring::Classification, UpAxis::Z); },
                ::testing::ThrowsMessage<Error>(HasSubstr(
                    "the scan has no classification to show (only LAS, LAZ and COPC files "
                    "carry one")));
}

/// The ASPRS table restated (LAS 1.4 R15, table 17): what each class must look like.
struct ClassLook {
    int code;
    const char* meaning;
    Rgba8 color;
};

TEST(ColoringTest, ClassificationColoursFollowTheAsprsClasses) {
    const ClassLook table[] = {
        {0, "never classified", {160, 160, 160, 255}},
        {1, "unclassified", {215, 215, 215, 255}},
        {2, "ground", {150, 95, 50, 255}},
        {3, "low vegetation", {150, 225, 100, 255}},
        {4, "medium vegetation", {60, 170, 60, 255}},
        {5, "high vegetation", {20, 100, 35, 255}},
        {6, "building", {235, 110, 35, 255}},
        {7, "low point (noise)", {230, 0, 230, 255}},
        {8, "model key-point / reserved", {255, 225, 0, 255}},
        {9, "water", {30, 100, 230, 255}},
        {10, "rail", {120, 70, 170, 255}},
        {11, "road surface", {70, 70, 85, 255}},
        {12, "overlap / reserved", {255, 255, 160, 255}},
        {13, "wire guard", {255, 170, 200, 255}},
        {14, "wire conductor", {0, 210, 210, 255}},
        {15, "transmission tower", {160, 30, 30, 255}},
        {16, "wire connector", {0, 110, 130, 255}},
        {17, "bridge deck", {205, 175, 130, 255}},
        {18, "high noise", {255, 40, 40, 255}},
    };
    for (const ClassLook& look : table) {
        SCOPED_TRACE(look.meaning);
        EXPECT_EQ(classificationColor(static_cast<std::uint8_t>(look.code)), look.color);
    }
    // The looks LiDAR users expect: ground brown (red over green over blue), vegetation green
    // and darker as it grows, water blue.
    const Rgba8 ground = classificationColor(2);
    EXPECT_TRUE(ground.r > ground.g && ground.g > ground.b);
    for (const int code : {3, 4, 5}) {
        const Rgba8 green = classificationColor(static_cast<std::uint8_t>(code));
        EXPECT_TRUE(green.g > green.r && green.g > green.b) << code;
    }
    EXPECT_GT(classificationColor(3).g, classificationColor(4).g);
    EXPECT_GT(classificationColor(4).g, classificationColor(5).g);
    const Rgba8 water = classificationColor(9);
    EXPECT_TRUE(water.b > water.r && water.b > water.g);
    // Every standard class its own colour, none the grey of the codes beyond them.
    const Rgba8 other{128, 128, 128, 255};
    for (int code = 0; code <= 18; ++code) {
        EXPECT_NE(classificationColor(static_cast<std::uint8_t>(code)), other) << code;
        for (int later = code + 1; later <= 18; ++later) {
            EXPECT_NE(classificationColor(static_cast<std::uint8_t>(code)),
                      classificationColor(static_cast<std::uint8_t>(later)))
                << code << " and " << later;
        }
    }
    for (const int code : {19, 31, 64, 255}) {
        EXPECT_EQ(classificationColor(static_cast<std::uint8_t>(code)), other) << code;
    }

    // pointColors maps each point's code through the table.
    PointCloud cloud = line(true);
    cloud.classifications.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        cloud.classifications[i] = static_cast<std::uint8_t>(i % 256);
    }
    const std::vector<Rgba8> colors = pointColors(cloud, Coloring::Classification, UpAxis::Z);
    ASSERT_EQ(colors.size(), cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        ASSERT_EQ(colors[i], classificationColor(cloud.classifications[i])) << i;
    }
    // Auto stays as it was: the scan's colour wins over its classification.
    EXPECT_EQ(pointColors(cloud, Coloring::Auto, UpAxis::Z), cloud.colors);
}

}  // namespace
}  // namespace subscan
