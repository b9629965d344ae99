#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "io/XyzReader.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::asBytes;
using test::decode;
using test::decodeError;
using test::expectPosition;
using ::testing::Contains;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

TEST(XyzReaderTest, ThreeColumnsWithAnySeparatorsCrLfBlankLinesAndNoFinalNewline) {
    const std::string file =
        "1 2 3\r\n"
        "\t4\t5\t6  \r\n"
        "\r\n"
        "7,8,9\n"
        "  \n"
        "-1 , +2.5 ,3e-1\n"
        "1;2 ; 3\n"
        "0.5, 0.25;\t0.125";
    const LoadedScan scan = decode(file, "points.xyz");
    EXPECT_EQ(scan.format, "xyz");
    EXPECT_EQ(scan.formatDetail, "text: x y z");
    EXPECT_THAT(scan.warnings, IsEmpty());
    const PointCloud& cloud = scan.cloud;
    ASSERT_EQ(cloud.size(), 6u);
    expectPosition(cloud, 0, 1, 2, 3);
    expectPosition(cloud, 1, 4, 5, 6);
    expectPosition(cloud, 2, 7, 8, 9);
    expectPosition(cloud, 3, -1, 2.5, 0.3);
    expectPosition(cloud, 4, 1, 2, 3);
    expectPosition(cloud, 5, 0.5, 0.25, 0.125);
    EXPECT_FALSE(cloud.hasColors());
    EXPECT_FALSE(cloud.hasNormals());
    EXPECT_FALSE(cloud.hasIntensities());
    // Bounds are kept in double straight from the parsed text.
    EXPECT_EQ(cloud.bounds.min, glm::dvec3(-1, 0.25, 0.125));
    EXPECT_EQ(cloud.bounds.max, glm::dvec3(7, 8, 9));
}

TEST(XyzReaderTest, TrailingSeparatorUtf8ByteOrderMarkAndUppercaseExponents) {
    const LoadedScan scan = decode(
        "\xEF\xBB\xBF"
        "1,2,3,\n4E0,5,6E+0,\n",
        "bom.csv");
    ASSERT_EQ(scan.cloud.size(), 2u);
    expectPosition(scan.cloud, 1, 4, 5, 6);
}

TEST(XyzReaderTest, FourColumnsAreIntensityKeptAsRead) {
    const LoadedScan scan = decode("1 2 3 -2048\n4 5 6 0.75\n", "i.xyz");
    EXPECT_EQ(scan.formatDetail, "text: x y z i");
    ASSERT_TRUE(scan.cloud.hasIntensities());
    EXPECT_THAT(scan.cloud.intensities, ElementsAre(-2048.0f, 0.75f));
    EXPECT_FALSE(scan.cloud.hasColors());
}

TEST(XyzReaderTest, SixIntegerColumnsWithin0To255AreColour) {
    // The first line alone would also pass as a normal; the second decides.
    const LoadedScan scan = decode("1 2 3 0 0 1\n4 5 6 255 128 7\n", "c.xyz");
    EXPECT_EQ(scan.formatDetail, "text: x y z r g b");
    ASSERT_TRUE(scan.cloud.hasColors());
    EXPECT_FALSE(scan.cloud.hasNormals());
    EXPECT_EQ(scan.cloud.colors[0], (Rgba8{0, 0, 1, 255}));
    EXPECT_EQ(scan.cloud.colors[1], (Rgba8{255, 128, 7, 255}));
}

TEST(XyzReaderTest, SixColumnsOfUnitLengthAreNormals) {
    const LoadedScan scan =
        decode("1 2 3 0 0 1\n4 5 6 0.6 -0.8 0\n7 8 9 0.577 0.577 0.577\n0 0 0 0 0 0\n", "n.xyz");
    EXPECT_EQ(scan.formatDetail, "text: x y z nx ny nz");
    ASSERT_TRUE(scan.cloud.hasNormals());
    EXPECT_FALSE(scan.cloud.hasColors());
    EXPECT_EQ(scan.cloud.normals[0], glm::vec3(0, 0, 1));
    EXPECT_EQ(scan.cloud.normals[1], glm::vec3(0.6f, -0.8f, 0));
    EXPECT_EQ(scan.cloud.normals[3], glm::vec3(0));  // "no normal", as some exporters write it
}

TEST(XyzReaderTest, SixColumnsThatAreNeitherColourNorNormalsAreAnError) {
    EXPECT_THAT(decodeError("1 2 3 10 20 30\n4 5 6 0.5 0.5 7\n", "x.xyz"),
                HasSubstr("the 3 values after x y z cannot be interpreted"));
    EXPECT_THAT(decodeError("1 2 3 10 20 300\n", "x.xyz"), HasSubstr("cannot be interpreted"));
}

TEST(XyzReaderTest, SevenNineAndTenColumnLayouts) {
    const LoadedScan seven = decode("1 2 3 -5 10 20 30\n", "seven.txt");
    EXPECT_EQ(seven.formatDetail, "text: x y z i r g b");
    EXPECT_EQ(seven.cloud.intensities[0], -5.0f);
    EXPECT_EQ(seven.cloud.colors[0], (Rgba8{10, 20, 30, 255}));

    const LoadedScan nine = decode("1 2 3 10 20 30 0 1 0\n", "nine.txt");
    EXPECT_EQ(nine.formatDetail, "text: x y z r g b nx ny nz");
    EXPECT_EQ(nine.cloud.colors[0], (Rgba8{10, 20, 30, 255}));
    EXPECT_EQ(nine.cloud.normals[0], glm::vec3(0, 1, 0));
    EXPECT_FALSE(nine.cloud.hasIntensities());

    const LoadedScan ten = decode("1 2 3 99 10 20 30 1 0 0\n", "ten.txt");
    EXPECT_EQ(ten.formatDetail, "text: x y z i r g b nx ny nz");
    EXPECT_EQ(ten.cloud.intensities[0], 99.0f);
    EXPECT_EQ(ten.cloud.colors[0], (Rgba8{10, 20, 30, 255}));
    EXPECT_EQ(ten.cloud.normals[0], glm::vec3(1, 0, 0));
}

TEST(XyzReaderTest, OtherColumnCountsReadXyzAndWarnOnce) {
    for (const int columns : {5, 8, 12}) {
        SCOPED_TRACE(columns);
        std::string file;
        for (int line = 0; line < 3; ++line) {
            for (int c = 0; c < columns; ++c) {
                file += fmt::format("{}{}", c == 0 ? "" : " ", line * 100 + c);
            }
            file += "\n";
        }
        const LoadedScan scan = decode(file, "wide.xyz");
        ASSERT_EQ(scan.cloud.size(), 3u);
        expectPosition(scan.cloud, 2, 200, 201, 202);
        EXPECT_FALSE(scan.cloud.hasColors());
        EXPECT_FALSE(scan.cloud.hasIntensities());
        ASSERT_EQ(scan.warnings.size(), 1u);
        EXPECT_THAT(scan.warnings[0],
                    HasSubstr(fmt::format("only the first 3 are read, as x y z, and the other {} "
                                          "are ignored",
                                          columns - 3)));
        EXPECT_THAT(scan.formatDetail,
                    HasSubstr(fmt::format("{} other columns ignored", columns - 3)));
    }
}

TEST(XyzReaderTest, LeicaPtsWithCountLine) {
    const LoadedScan scan =
        decode("3\r\n1 2 3 -2048 255 0 0\r\n4 5 6 2047 0 255 0\r\n7 8 9 0 0 0 255\r\n", "scan.pts");
    EXPECT_EQ(scan.format, "xyz");
    EXPECT_EQ(scan.formatDetail, "PTS text: x y z i r g b");
    const PointCloud& cloud = scan.cloud;
    ASSERT_EQ(cloud.size(), 3u);
    expectPosition(cloud, 2, 7, 8, 9);
    EXPECT_THAT(cloud.intensities, ElementsAre(-2048.0f, 2047.0f, 0.0f));
    EXPECT_EQ(cloud.colors[1], (Rgba8{0, 255, 0, 255}));
}

TEST(XyzReaderTest, MultiScanPtsRepeatsCountLineAndBlock) {
    const LoadedScan scan = decode("2\n1 1 1 5\n2 2 2 6\n\n0\n1\n3 3 3 7\n", "multi.pts");
    EXPECT_EQ(scan.formatDetail, "PTS text: x y z i");
    ASSERT_EQ(scan.cloud.size(), 3u);
    expectPosition(scan.cloud, 2, 3, 3, 3);
    EXPECT_THAT(scan.cloud.intensities, ElementsAre(5.0f, 6.0f, 7.0f));
}

TEST(XyzReaderTest, PtsCountsThatDoNotMatchThePointsAreErrors) {
    EXPECT_THAT(decodeError("3\n1 2 3\n4 5 6\n", "x.pts"),
                HasSubstr("the PTS count on line 1 says 3 points, but 2 follow"));
    EXPECT_THAT(decodeError("1\n1 2 3\n4 5 6\n", "x.pts"),
                HasSubstr("the PTS count on line 1 says 1 point, but 2 follow"));
    EXPECT_THAT(decodeError("1\n1 2 3\n2\n4 5 6\n", "x.pts"),
                HasSubstr("the PTS count on line 3 says 2 points, but 1 follow"));
    // Never trusted for allocation: a huge count only leads to the mismatch.
    EXPECT_THAT(decodeError("4000000000\n1 2 3\n", "x.pts"),
                HasSubstr("says 4000000000 points, but 1 follow"));
    EXPECT_THAT(decodeError("1\n1 2 3\n2.5\n4 5 6\n", "x.pts"),
                HasSubstr("line 3 has only 1 value"));
}

TEST(XyzReaderTest, HeaderNamesMapColumnsInAnyOrder) {
    const LoadedScan scan =
        decode("x,y,z,nx,ny,nz,r,g,b\n1,2,3,0,0,1,10,20,30\n4,5,6,1,0,0,40,50,60\n", "h.csv");
    EXPECT_EQ(scan.formatDetail, "text: x y z nx ny nz r g b");
    EXPECT_THAT(scan.warnings, IsEmpty());
    ASSERT_EQ(scan.cloud.size(), 2u);
    EXPECT_EQ(scan.cloud.normals[0], glm::vec3(0, 0, 1));
    EXPECT_EQ(scan.cloud.colors[1], (Rgba8{40, 50, 60, 255}));

    const LoadedScan permuted = decode("Z;Intensity;Y;X\n3;0.5;2;1\n", "p.csv");
    EXPECT_EQ(permuted.formatDetail, "text: z i y x");
    expectPosition(permuted.cloud, 0, 1, 2, 3);
    EXPECT_EQ(permuted.cloud.intensities[0], 0.5f);

    const LoadedScan semicolons =
        decode("x;y;z;normal_x;normal_y;normal_z\n1;2;3;0;1;0\n", "s.csv");
    EXPECT_EQ(semicolons.cloud.normals[0], glm::vec3(0, 1, 0));

    // The header decides even where a guess would say otherwise: these six are colours.
    const LoadedScan quoted =
        decode("\"X\",\"Y\",\"Z\",\"Red\",\"Green\",\"Blue\"\n1,2,3,0,0,1\n", "q.csv");
    ASSERT_TRUE(quoted.cloud.hasColors());
    EXPECT_EQ(quoted.cloud.colors[0], (Rgba8{0, 0, 1, 255}));
}

TEST(XyzReaderTest, CommentHeadersAreNamesAndFloatColoursAreScaled) {
    const LoadedScan cloudCompare =
        decode("//X Y Z Rf Gf Bf Intensity\n1 2 3 1.0 0.5 0 7\n4 5 6 0.2 2 -1 8\n", "cc.txt");
    EXPECT_EQ(cloudCompare.formatDetail, "text: x y z rf gf bf i");
    EXPECT_EQ(cloudCompare.cloud.colors[0], (Rgba8{255, 128, 0, 255}));
    EXPECT_EQ(cloudCompare.cloud.colors[1], (Rgba8{51, 255, 0, 255}));  // clamped
    EXPECT_THAT(cloudCompare.cloud.intensities, ElementsAre(7.0f, 8.0f));

    const LoadedScan hash = decode("# x y z scalar_intensity\n1 2 3 4\n", "hash.txt");
    EXPECT_EQ(hash.formatDetail, "text: x y z i");
}

TEST(XyzReaderTest, ColourValuesClampAndOtherEncodingsAreRecognised) {
    const LoadedScan bytes = decode("x y z r g b\n1 2 3 -5 255 128\n", "clamp.xyz");
    EXPECT_EQ(bytes.cloud.colors[0], (Rgba8{0, 255, 128, 255}));

    // PDAL writes LAS colours as 16-bit values.
    const LoadedScan words = decode("X,Y,Z,Red,Green,Blue\n1,2,3,65535,0,32896\n", "pdal.csv");
    EXPECT_EQ(words.formatDetail, "text: x y z r g b (16-bit colour)");
    EXPECT_EQ(words.cloud.colors[0], (Rgba8{255, 0, 128, 255}));

    // Fractions no larger than 1 under the names r g b are 0..1 floats.
    const LoadedScan fractions = decode("x y z r g b\n1 2 3 1.0 0.5 0\n", "unit.xyz");
    EXPECT_EQ(fractions.formatDetail, "text: x y z rf gf bf");
    EXPECT_EQ(fractions.cloud.colors[0], (Rgba8{255, 128, 0, 255}));
}

TEST(XyzReaderTest, SixteenBitColourBeyondEightBitsIsMarkedCut) {
    // convert warns of it as of LAS colour; it cut 16-bit text colour to 8 bits without a word.
    const auto cut = [](const std::string& text) {
        return decode(text, "colour.csv").cloud.colorCutTo8Bits;
    };
    EXPECT_TRUE(cut("X,Y,Z,Red,Green,Blue\n1,2,3,65535,0,1000\n"));
    // 8-bit values, or 16-bit ones that are 8-bit values times 257 (32896 = 128 x 257), lose
    // nothing.
    EXPECT_FALSE(cut("X,Y,Z,Red,Green,Blue\n1,2,3,255,0,100\n"));
    EXPECT_FALSE(cut("X,Y,Z,Red,Green,Blue\n1,2,3,65535,0,32896\n"));
    // A dropped point's colour is not written.
    EXPECT_FALSE(cut("X,Y,Z,Red,Green,Blue\n1,2,3,65535,0,0\nnan,2,3,1000,1000,1000\n"));
}

/// 150 dark points ("x y z r g b", values 0..149), then 850 in 16-bit colour (up to 64955), and
/// one to drop.
std::string darkStartThenSixteenBit(bool header) {
    std::string text = header ? "x y z red green blue\n" : "";
    for (int i = 0; i < 1000; ++i) {
        const int value = i < 150 ? i : 20000 + 45 * i;
        text += fmt::format("{} 0 0 {} {} {}\n", i, value, value, value);
    }
    return text + "nan 0 0 0 0 0\n";
}

TEST(XyzReaderTest, ColourEncodingIsJudgedFromEveryLineNotTheFirstOnes) {
    // The first 100 lines decided: later 16-bit values were clamped to 255 (white), silently.
    for (const bool header : {false, true}) {
        SCOPED_TRACE(header ? "header" : "no header");
        const LoadedScan scan = decode(darkStartThenSixteenBit(header), "dark.xyz");
        EXPECT_EQ(scan.formatDetail, "text: x y z r g b (16-bit colour)");
        ASSERT_EQ(scan.cloud.size(), 1000u);
        EXPECT_EQ(scan.cloud.colors[149].r, 1);    // 149 / 257, rounded
        EXPECT_EQ(scan.cloud.colors[150].r, 104);  // 26750 / 257
        EXPECT_EQ(scan.cloud.colors[999].r, 253);  // 64955 / 257
        EXPECT_TRUE(scan.cloud.colorCutTo8Bits);   // as the second reading found
        // Read twice, warned once.
        EXPECT_THAT(scan.warnings, ElementsAre(HasSubstr("dropped 1 of 1001 points")));
    }
    // Fractions no larger than 1 after integer lines: 0..1 floats, the first lines too.
    std::string unit = "x y z r g b\n";
    for (int i = 0; i < 120; ++i) {
        unit += "0 0 0 1 0 1\n";
    }
    unit += "0 0 0 0.5 0.25 1\n";
    const LoadedScan units = decode(unit, "unit.xyz");
    EXPECT_EQ(units.formatDetail, "text: x y z rf gf bf");
    EXPECT_EQ(units.cloud.colors[0], (Rgba8{255, 0, 255, 255}));
    EXPECT_EQ(units.cloud.colors[120], (Rgba8{128, 64, 255, 255}));
}

TEST(XyzReaderTest, HeaderColumnsItDoesNotKnowAreNamedInOneWarning) {
    const LoadedScan scan = decode(
        "Scan of the yard\nX,Y,Z,Classification,Red,Green,Blue,GpsTime\n"
        "1,2,3,2,10,20,30,1e9\n",
        "pdal.csv");
    EXPECT_EQ(scan.formatDetail, "text: x y z r g b, 2 other columns ignored");
    EXPECT_EQ(scan.cloud.colors[0], (Rgba8{10, 20, 30, 255}));
    EXPECT_THAT(
        scan.warnings,
        ElementsAre("the columns 'Classification', 'GpsTime' named on line 2 are not read"));
}

TEST(XyzReaderTest, HeaderWithAnotherColumnCountIsReportedAndColumnsAreGuessed) {
    const LoadedScan scan = decode("X Y Z R G B\n1 2 3 4\n", "h.xyz");
    EXPECT_EQ(scan.formatDetail, "text: x y z i");
    EXPECT_THAT(scan.warnings,
                ElementsAre("the header on line 1 names 6 columns, but the points have 4 values; "
                            "the columns are guessed from the values instead"));
}

TEST(XyzReaderTest, CommentLinesAnywhereAreSkipped) {
    const LoadedScan scan =
        decode("# exported by hand\n1 2 3\n  // a note\n# another\n4 5 6\n", "c.xyz");
    ASSERT_EQ(scan.cloud.size(), 2u);
    expectPosition(scan.cloud, 1, 4, 5, 6);
}

TEST(XyzReaderTest, DecimalCommasWithSemicolonSeparators) {
    const LoadedScan scan = decode("X;Y;Z\n1,5;2,25;-3\n4;5,5;6\n", "excel.csv");
    EXPECT_EQ(scan.formatDetail, "text: x y z (decimal commas)");
    ASSERT_EQ(scan.cloud.size(), 2u);
    expectPosition(scan.cloud, 0, 1.5, 2.25, -3);
    expectPosition(scan.cloud, 1, 4, 5.5, 6);

    // Commas in a line without ';' separate values, even in a file with no '.' at all.
    const LoadedScan mixed = decode("1,2,3\n4;5;6\n", "mixed.csv");
    EXPECT_EQ(mixed.formatDetail, "text: x y z");
    EXPECT_EQ(mixed.cloud.size(), 2u);
}

TEST(XyzReaderTest, NanAndInfiniteCoordinatesAreDroppedWithAWarning) {
    const LoadedScan scan =
        decode("1 2 3 10\nnan 0 0 11\n4 5 6 12\n0 -inf 0 13\n0 0 1e999 14\n", "nan.xyz");
    ASSERT_EQ(scan.cloud.size(), 2u);
    EXPECT_THAT(scan.cloud.intensities, ElementsAre(10.0f, 12.0f));
    EXPECT_THAT(scan.warnings, Contains(HasSubstr("dropped 3 of 5 points")));
}

TEST(XyzReaderTest, NumbersAreCorrectlyRoundedLikeStrtod) {
    // Plain decimals take a shortcut past fast_float; both must give the nearest double.
    std::mt19937_64 random(7);
    std::vector<std::string> numbers{"0",
                                     "-0",
                                     "1.",
                                     ".5",
                                     "-.25",
                                     "+7",
                                     "9007199254740993",
                                     "123456789012345678901234",
                                     "0.1234567890123456789012",
                                     "1.7976931348623157e308",
                                     "4.9e-324",
                                     "2.2250738585072011e-308",
                                     "1e22",
                                     "1e23",
                                     "0.000000000000000000000001"};
    for (int i = 0; i < 2000; ++i) {
        const std::string digits = std::to_string(random());
        const std::size_t length = 1 + random() % digits.size();
        const std::size_t point = random() % (length + 1);
        numbers.push_back(fmt::format("{}{}.{}", random() % 2 ? "-" : "", digits.substr(0, point),
                                      digits.substr(point, length - point)));
    }
    for (const std::string& number : numbers) {
        SCOPED_TRACE(number);
        const double expected = std::strtod(number.c_str(), nullptr);
        if (std::abs(expected) > kMaxCoordinate) {
            // Such coordinates are dropped as corrupt, so read the number as an intensity (a
            // float: both sides round the same double).
            const LoadedScan scan = decode("0 0 0 " + number + "\n", "one.xyz");
            EXPECT_EQ(scan.cloud.intensities.at(0), saturateToFloat(expected));
            continue;
        }
        const LoadedScan scan = decode(number + " 0 0\n", "one.xyz");
        // Exact: both sides are the double nearest to the decimal text.
        EXPECT_EQ(scan.cloud.bounds.min.x, expected);
    }
}

TEST(XyzReaderTest, LargeCoordinatesKeepTheirPrecision) {
    const LoadedScan scan =
        decode("500000.125 5400000.5 250.25\n500010.375 5400020.75 260.5\n", "utm.xyz");
    // Bounds stay in double: exact.
    EXPECT_EQ(scan.cloud.bounds.min, glm::dvec3(500000.125, 5400000.5, 250.25));
    EXPECT_EQ(scan.cloud.bounds.max, glm::dvec3(500010.375, 5400020.75, 260.5));
    // Floats relative to the centre of a 20-unit cloud: steps of about 1e-6.
    EXPECT_NEAR(scan.cloud.fileCoordinates(1).y, 5400020.75, 4e-6);
}

TEST(XyzReaderTest, TheCoordinatesDecimalsAreTheirStep) {
    // The most decimals of any coordinate, less the exponent (2.5e-2 has 3); the colour's and
    // intensity's decimals do not count.
    EXPECT_EQ(decode("500000.12 5400000.5 250\n1 2.5e-2 3\n", "a.xyz").cloud.coordinateStep, 1e-3);
    EXPECT_EQ(decode("500000 5400000 250 0.123456\n", "i.xyz").cloud.coordinateStep, 1.0);
    EXPECT_EQ(decode("1.5e3 2e2 3E+2\n", "e.xyz").cloud.coordinateStep, 100.0);
    EXPECT_EQ(decode("1,25;2,5;3\n", "comma.csv").cloud.coordinateStep, 0.01);
}

TEST(XyzReaderTest, ContentDetectionForUnhelpfulExtensions) {
    EXPECT_EQ(decode("1 2 3\n4 5 6\n", "scan.dat").format, "xyz");
    EXPECT_EQ(decode("X,Y,Z,R,G,B\n1,2,3,4,5,6\n", "scan.dat").format, "xyz");
    EXPECT_EQ(decode("# comment\n//X Y Z\n\n2\n1 2 3\n4 5 6\n", "scan.dat").format, "xyz");

    EXPECT_TRUE(looksLikePointText(asBytes("1 2 3")));
    EXPECT_TRUE(looksLikePointText(asBytes("\xEF\xBB\xBFx;y;z\r\n1;2;3\r\n")));
    // The first data line may run past the part that is looked at.
    EXPECT_TRUE(looksLikePointText(asBytes("x y z\n1 2 " + std::string(5000, '3') + "\n")));
    std::string manyLines;
    while (manyLines.size() < 10000) {
        manyLines += "1.5 2.5 3.5\n";
    }
    EXPECT_TRUE(looksLikePointText(asBytes(manyLines)));

    EXPECT_FALSE(looksLikePointText(asBytes("")));
    EXPECT_FALSE(looksLikePointText(asBytes("1 2\n3 4\n")));
    EXPECT_FALSE(looksLikePointText(asBytes("Dear reader,\nthis is prose.\n")));
    EXPECT_FALSE(looksLikePointText(asBytes("v 1 2 3\nv 4 5 6\nf 1 2 3\n")));  // OBJ
    EXPECT_FALSE(looksLikePointText(asBytes("1 2 3 four\n")));
    EXPECT_FALSE(looksLikePointText(asBytes(std::string("1 2 3\n\0\x01\x02", 9))));
    EXPECT_FALSE(
        looksLikePointText(asBytes("\x7f"
                                   "ELF\x02\x01\x01")));
    EXPECT_THAT(decodeError(std::string("\x89PNG\r\n\x1a\n\0\0", 10), "scan.dat"),
                HasSubstr("format is unknown"));
}

TEST(XyzReaderTest, BadInputsGiveOneClearSentence) {
    struct Case {
        const char* name;
        std::string file;
        const char* expected;
    };
    std::string nulAfterTheStart;
    while (nulAfterTheStart.size() < 6000) {
        nulAfterTheStart += "1 2 3\n";
    }
    nulAfterTheStart += std::string("4 5\0 6\n", 7);
    const Case cases[] = {
        {"non-numeric", "1 2 3\n4 five 6\n", "line 2 has the non-numeric value 'five'"},
        {"number glued to text", "1 2 3\n4 5 6abc\n", "line 2 has the non-numeric value '6abc'"},
        {"header after data", "X Y Z\n1 2 3\nX Y Z\n4 5 6\n",
         "line 3 has the non-numeric value 'X'"},
        {"non-numeric first line", "1 2 three\n", "line 1 has the non-numeric value 'three'"},
        {"more values", "1 2 3\n\n4 5 6 7\n",
         "line 3 has 4 values, but the first point (line 1) "
         "has 3"},
        {"fewer values", "# c\n1 2 3 4\n5 6 7\n",
         "line 3 has 3 values, but the first point "
         "(line 2) has 4"},
        {"one value", "1 2 3\n4\n", "line 2 has 1 value, but the first point"},
        {"two columns", "1 2\n3 4\n",
         "line 1 has only 2 values; each point needs at least x, y "
         "and z"},
        {"one fractional value", "0.5\n1 2 3\n", "line 1 has only 1 value"},
        {"empty value", "1,,2,3\n", "line 1 has an empty value"},
        {"leading separator", "1,2,3\n,4,5,6\n", "line 2 has an empty value"},
        {"only headers", "X Y Z\n# nothing here\n",
         "it contains no points, only 2 header or "
         "comment lines"},
        {"one very long line of text", std::string(100000, 'a') + "\n",
         "it contains no points, only 1 header or comment line"},
        {"only blank lines", "\n \r\n\t\n", "it contains no points"},
        {"only a zero count", "0\n", "it contains no points"},
        {"all NaN", "nan 0 0\n0 nan 0\n", "all 2 points have NaN"},
        {"NUL at the start", std::string("1 2 3\n\0\0\0\0", 10), "contains NUL bytes"},
        {"NUL later", nulAfterTheStart, "line 1001 contains NUL bytes"},
        {"UTF-16",
         std::string("\xFF\xFE"
                     "1\0 \0"
                     "2\0",
                     8),
         "UTF-16"},
        {"classic Mac line ends", "1 2 3\r4 5 6\r", "CR alone"},
        {"ESRI grid", "ncols 2\nnrows 1\nxllcorner 0\nyllcorner 0\ncellsize 1\n5 6\n",
         "ESRI ASCII grid"},
        {"PTS count mismatch", "5\n1 2 3\n", "says 5 points, but 1 follow"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        EXPECT_THAT(decodeError(c.file, "x.xyz"), HasSubstr(c.expected));
    }
}

TEST(XyzReaderTest, CliReportsABadFileOnOneStderrLine) {
    const test::TempDir directory;
    struct Case {
        const char* name;
        std::string contents;
        const char* expected;
    };
    const Case cases[] = {
        {"letters.xyz", "1 2 3\n4 x 6\n", "line 2 has the non-numeric value 'x'"},
        {"ragged.csv", "1,2,3\n4,5\n", "line 2 has 2 values, but the first point (line 1) has 3"},
        {"short.pts", "2\n1 2 3 0 1 2 3\n", "the PTS count on line 1 says 2 points, but 1 follow"},
        {"binary.txt", std::string("\0\1\2\3", 4), "contains NUL bytes"},
        {"header.csv", "X,Y,Z\n", "contains no points"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        const std::filesystem::path path = directory.write(c.name, c.contents);
        const test::CommandResult result = test::runSubscan({"info", path.string()});
        EXPECT_EQ(result.exitCode, 1);
        EXPECT_THAT(result.out, IsEmpty());
        EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
        EXPECT_TRUE(result.err.ends_with("\n")) << result.err;
        EXPECT_THAT(result.err, HasSubstr("subscan: " + path.string() + ": "));
        EXPECT_THAT(result.err, HasSubstr(c.expected));
    }
}

TEST(XyzReaderTest, TwoHundredThousandLinesParseCorrectly) {
    constexpr int kLines = 200000;
    std::string file = "//X Y Z R G B\n";
    for (int i = 0; i < kLines; ++i) {
        file += fmt::format("{:.3f} {} {:.6f} {} {} {}\n", i * 0.001, -(i % 1000), i * 1e-6,
                            i % 256, (i / 256) % 256, 255 - i % 256);
    }
    std::vector<double> progress;
    const LoadedScan scan = decodeScan(asBytes(file), ScanFormat::Xyz,
                                       [&](double fraction) { progress.push_back(fraction); });
    const PointCloud& cloud = scan.cloud;
    ASSERT_EQ(cloud.size(), static_cast<std::size_t>(kLines));
    EXPECT_THAT(scan.warnings, IsEmpty());
    // Bounds are doubles parsed from the same decimal text as these literals: exact.
    EXPECT_EQ(cloud.bounds.min, glm::dvec3(0, -999, 0));
    EXPECT_EQ(cloud.bounds.max, glm::dvec3(199.999, 0, 0.199999));
    for (const int i : {0, 1, 4242, 123457, kLines - 1}) {
        SCOPED_TRACE(i);
        const glm::dvec3 p = cloud.fileCoordinates(static_cast<std::size_t>(i));
        // y spans 1000 units, so float positions reach 500 from the centre, where float steps
        // are 6e-5: rounding errs by up to 3e-5.
        EXPECT_NEAR(p.x, i * 0.001, 4e-5);
        EXPECT_NEAR(p.y, -(i % 1000), 4e-5);
        EXPECT_NEAR(p.z, i * 1e-6, 4e-5);
        EXPECT_EQ(
            cloud.colors[static_cast<std::size_t>(i)],
            (Rgba8{static_cast<std::uint8_t>(i % 256), static_cast<std::uint8_t>((i / 256) % 256),
                   static_cast<std::uint8_t>(255 - i % 256), 255}));
    }
    // Several megabytes: progress comes a few times, in order, and ends at 1.
    ASSERT_GE(progress.size(), 2u);
    EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
    EXPECT_EQ(progress.back(), 1.0);
}

}  // namespace
}  // namespace subscan
