// What --color shows: each colouring against its rule, Auto's choice, and the errors.
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
    for (const Coloring coloring : {Coloring::Auto, Coloring::Rgb, Coloring::Intensity,
                                    Coloring::Height, Coloring::Uniform}) {
        EXPECT_EQ(parseColoring(toString(coloring)), coloring);
    }
    try {
        parseColoring("rainbow");
        FAIL() << "accepted 'rainbow'";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), HasSubstr("auto, rgb, intensity, height, uniform"));
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
}

}  // namespace
}  // namespace subscan
