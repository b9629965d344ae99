#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "io/PointRecordSource.h"
#include "io/ScanLoader.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::runSubscan;
using ::testing::HasSubstr;

/// Converts `source` to `output`, expecting success and its one line.
void convert(const std::string& source, const std::filesystem::path& output) {
    const test::CommandResult result = runSubscan({"convert", source, "-o", output.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_EQ(test::lineCount(result.out), 1u) << result.out;
    EXPECT_THAT(result.out, HasSubstr(output.string() + ": "));
}

TEST(ConvertCommandTest, SyntheticSceneToEveryFormatAndBack) {
    const test::TempDir dir;
    const std::string source = "synthetic:sphere?points=500";
    const LoadedScan original = loadScan(source);
    ASSERT_TRUE(original.cloud.hasColors() && original.cloud.hasNormals());
    // Upper case extensions pick the format as well.
    for (const std::string name :
         {"sphere.ply", "sphere.las", "sphere.pcd", "sphere.xyz", "SPHERE.PLY"}) {
        SCOPED_TRACE(name);
        const auto output = dir / name;
        const test::CommandResult result = runSubscan({"convert", source, "-o", output.string()});
        ASSERT_EQ(result.exitCode, 0) << result.err;
        EXPECT_EQ(result.out, output.string() + ": 500 points written as " +
                                  (name.ends_with(".las")   ? "LAS 1.2"
                                   : name.ends_with(".pcd") ? "PCD"
                                   : name.ends_with(".xyz") ? "XYZ text"
                                                            : "PLY") +
                                  " (from " + source + ")\n");
        const LoadedScan read = loadScan(output.string());
        // A unit sphere: float positions are good to 6e-8 on either side, the LAS scale is 1e-9
        // (offset -1, reaching 2 m); 1e-6 leaves room for both.
        test::expectPositionsNear(read.cloud, original.cloud, 1e-6);
        EXPECT_EQ(read.cloud.colors, original.cloud.colors);
        if (name.ends_with(".las")) {
            EXPECT_FALSE(read.cloud.hasNormals());
            EXPECT_THAT(result.err, HasSubstr("warning: " + output.string() +
                                              ": LAS 1.2 output holds no normals"));
        } else {
            EXPECT_EQ(read.cloud.normals, original.cloud.normals);
            EXPECT_TRUE(result.err.empty()) << result.err;
        }
    }
}

TEST(ConvertCommandTest, EstimatedNormalsReplaceTheFilesAndFollowTheSurface) {
    const test::TempDir dir;
    const std::string source = "synthetic:sphere?points=5000";
    const LoadedScan original = loadScan(source);  // the scene's exact normals
    const auto output = dir / "sphere.ply";
    const test::CommandResult result =
        runSubscan({"convert", source, "-o", output.string(), "--estimate-normals"});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const LoadedScan read = loadScan(output.string());
    ASSERT_EQ(read.cloud.normals.size(), original.cloud.size());
    double sum = 0.0;
    for (std::size_t i = 0; i < read.cloud.size(); ++i) {
        // No sensor: the sign is arbitrary, the line is the surface's.
        sum += std::acos(std::min(1.0, std::abs(static_cast<double>(glm::dot(
                                           read.cloud.normals[i], original.cloud.normals[i])))));
    }
    // 5000 points with the scanner's noise on a unit sphere: measured 0.53 degrees; 5 is far
    // below what unrelated normals give (57 degrees on average).
    EXPECT_LT(sum / static_cast<double>(read.cloud.size()), 5.0 * std::numbers::pi / 180.0);

    const auto las = dir / "sphere.las";
    const test::CommandResult refused =
        runSubscan({"convert", source, "-o", las.string(), "--estimate-normals"});
    EXPECT_EQ(refused.exitCode, 1);
    EXPECT_EQ(test::lineCount(refused.err), 1u) << refused.err;
    EXPECT_THAT(refused.err, HasSubstr("cannot hold normals"));
    EXPECT_FALSE(std::filesystem::exists(las));
    // LAZ holds normals as extra bytes, but writes records, not estimates: the way there named.
    const auto laz = dir / "sphere.laz";
    const test::CommandResult twoSteps =
        runSubscan({"convert", source, "-o", laz.string(), "--estimate-normals"});
    EXPECT_EQ(twoSteps.exitCode, 1);
    EXPECT_THAT(twoSteps.err, HasSubstr("then that PLY to LAZ or COPC"));
    EXPECT_FALSE(std::filesystem::exists(laz));
}

TEST(ConvertCommandTest, NormalsSurviveLazAndCopcAsPdalsExtraBytes) {
    // LAZ and COPC from a cloud with normals hold them as the float extra bytes NormalX, NormalY
    // and NormalZ (PDAL's names); the LAS reader finds them by their descriptors. Floats stored
    // as they are: equal bit for bit.
    const test::TempDir dir;
    const std::string source = "synthetic:sphere?points=2000";
    const LoadedScan original = loadScan(source);
    ASSERT_TRUE(original.cloud.hasNormals());
    const auto ply = dir / "sphere.ply";
    convert(source, ply);
    for (const std::string name : {"sphere.laz", "sphere.copc.laz"}) {
        SCOPED_TRACE(name);
        const auto output = dir / name;
        convert(ply.string(), output);
        const LoadedScan read = loadScan(output.string());
        ASSERT_EQ(read.cloud.size(), original.cloud.size());
        // COPC reorders the points by node: the same normals as a multiset, each still with
        // its point: the sphere's are radial (the unit sphere about the origin; positions at
        // the file's scale, far finer than 1e-4).
        const auto lexicographic = [](const glm::vec3& l, const glm::vec3& r) {
            return std::tie(l.x, l.y, l.z) < std::tie(r.x, r.y, r.z);
        };
        std::vector<glm::vec3> expected = original.cloud.normals, got = read.cloud.normals;
        std::sort(expected.begin(), expected.end(), lexicographic);
        std::sort(got.begin(), got.end(), lexicographic);
        EXPECT_EQ(got, expected);
        for (std::size_t i = 0; i < read.cloud.size(); ++i) {
            const glm::dvec3 radial = glm::normalize(read.cloud.fileCoordinates(i));
            ASSERT_LT(glm::length(glm::dvec3(read.cloud.normals[i]) - radial), 1e-4) << i;
        }
    }
}

TEST(ConvertCommandTest, RealLasToEveryFormatKeepsPointsAndColours) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const auto source = data / "autzen_trim.las";
    const LoadedScan original = loadScan(source.string());
    ASSERT_EQ(original.cloud.size(), 110000u);
    const test::TempDir dir;
    for (const std::string name : {"autzen.las", "autzen.ply", "autzen.pcd", "autzen.xyz"}) {
        SCOPED_TRACE(name);
        const auto output = dir / name;
        convert(source.string(), output);
        const LoadedScan read = loadScan(output.string());
        ASSERT_EQ(read.cloud.size(), 110000u);
        // Half the source's 0.01 m scale: far more than what converting adds (float rounding in
        // memory at ~1 km from the centre, 3e-5 m, and the new LAS file's finer scale).
        test::expectPositionsNear(read.cloud, original.cloud, 0.005);
        EXPECT_EQ(read.cloud.colors, original.cloud.colors);
        EXPECT_EQ(read.cloud.intensities, original.cloud.intensities);
        if (name.ends_with(".las")) {
            EXPECT_EQ(read.cloud.classifications, original.cloud.classifications);
        } else {
            EXPECT_FALSE(read.cloud.hasClassifications());
        }
    }
}

TEST(ConvertCommandTest, ClassificationSurvivesLasToLasAndIsNamedWhereItCannot) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    // LAS 1.4 point format 7 to LAS (through its records, format 7 again): autzen's codes are 1
    // and 2, unchanged; to PLY, which has no classification, with a warning.
    const auto source = data / "autzen_trim_las14_pf7.las";
    const LoadedScan original = loadScan(source.string());
    ASSERT_TRUE(original.cloud.hasClassifications());
    const test::TempDir dir;
    const test::CommandResult las =
        runSubscan({"convert", source.string(), "-o", (dir / "a.las").string()});
    ASSERT_EQ(las.exitCode, 0) << las.err;
    EXPECT_TRUE(las.err.empty()) << las.err;
    EXPECT_EQ(loadScan((dir / "a.las").string()).cloud.classifications,
              original.cloud.classifications);
    const test::CommandResult ply =
        runSubscan({"convert", source.string(), "-o", (dir / "a.ply").string()});
    ASSERT_EQ(ply.exitCode, 0) << ply.err;
    EXPECT_THAT(ply.err,
                HasSubstr("warning: " + (dir / "a.ply").string() +
                          ": PLY output holds no classification codes; they are not written"));
}

TEST(ConvertCommandTest, AMeshsFacesDroppedByLazAreNamed) {
    // LAZ and COPC are written from point records, which hold no faces: they were dropped
    // without a word, while LAS output warned. A text PLY loads whole, a binary one streams.
    const test::TempDir dir;
    const std::string header =
        "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const auto text = dir.write(
        "text.ply", "ply\nformat ascii 1.0\n" + header + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    std::string binary = "ply\nformat binary_little_endian 1.0\n" + header;
    for (const float value : {0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f}) {
        binary.append(reinterpret_cast<const char*>(&value), sizeof value);
    }
    binary += '\x03';
    for (const std::int32_t index : {0, 1, 2}) {
        binary.append(reinterpret_cast<const char*>(&index), sizeof index);
    }
    const auto binaryPly = dir.write("binary.ply", binary);
    for (const auto& [input, output] :
         {std::pair{text, dir / "text.laz"}, std::pair{binaryPly, dir / "binary.copc.laz"}}) {
        const test::CommandResult result =
            runSubscan({"convert", input.string(), "-o", output.string()});
        ASSERT_EQ(result.exitCode, 0) << result.err;
        EXPECT_THAT(result.err, HasSubstr(input.string() + ": its faces (1) are not kept"));
    }
}

TEST(ConvertCommandTest, APcdKeepsItsSensorAndNamesTheGridItDrops) {
    // A 2 x 2 organised cloud whose sensor stood 10 below it: the PCD written keeps the sensor
    // (it was always the origin) and says that the grid is not kept (it was dropped unsaid).
    const test::TempDir dir;
    const auto input = dir.write("grid.pcd",
                                 "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                                 "WIDTH 2\nHEIGHT 2\nVIEWPOINT 0.5 0.5 -10 1 0 0 0\nPOINTS 4\n"
                                 "DATA ascii\n0 0 0\n1 0 0\n0 1 0\n1 1 0.1\n");
    const auto output = dir / "list.pcd";
    const test::CommandResult result =
        runSubscan({"convert", input.string(), "-o", output.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.err, HasSubstr("the input's organised grid (2 x 2) is not kept"));
    const LoadedScan read = loadScan(output.string());
    ASSERT_TRUE(read.sensor.has_value());
    EXPECT_EQ(read.sensor->position, glm::dvec3(0.5, 0.5, -10));
}

TEST(ConvertCommandTest, TextOfMillimetresKeepsThemInPlyAndPcd) {
    // 18 km of millimetre coordinates about 509 km from the origin: float rounds by 16 mm
    // there, less than the millionth of the extent (18 mm) that was allowed for every input
    // without a grid (found by the outside hunt). The text's decimals say millimetres, so
    // doubles are written.
    const test::TempDir dir;
    std::vector<glm::dvec3> positions{{509000.0, 509000.0, 100.0}};  // the centre: memory's origin
    for (int i = -50; i <= 50; ++i) {
        positions.emplace_back(509000.0 + 180.001 * i, 509000.0 - 170.007 * i, 100.0 + 0.013 * i);
    }
    std::string text;
    for (const glm::dvec3& p : positions) {
        text += fmt::format("{:.3f} {:.3f} {:.3f}\n", p.x, p.y, p.z);
    }
    const auto input = dir.write("mm.xyz", text);
    for (const std::string name : {"mm.ply", "mm.pcd"}) {
        SCOPED_TRACE(name);
        const auto output = dir / name;
        convert(input.string(), output);
        // Floats relative to the centre, 9 km at most, round by 0.49 mm when the text is read
        // and again when the output is.
        test::expectPositionsNear(loadScan(output.string()).cloud, test::cloudOf(positions), 1e-3);
    }
}

/// A LAS 1.2 file of point format 0 on a millimetre grid (scale 0.001) about UTM-like offsets,
/// with its stored integers, built here byte by byte from the LAS 1.2 specification.
struct MillimetreSurvey {
    std::string bytes;
    std::vector<std::array<std::int32_t, 3>> stored;
    glm::dvec3 offset{412345.0, 5123456.0, 100.0};
    static constexpr double kScale = 0.001;

    glm::dvec3 fileCoordinates(std::size_t i) const {
        return {stored[i][0] * kScale + offset.x, stored[i][1] * kScale + offset.y,
                stored[i][2] * kScale + offset.z};
    }
};

/// `count` points spanning `spanMetres` in x and y (the first two at opposite corners) and 500 m
/// in z, each coordinate a pseudo-random whole number of millimetres.
MillimetreSurvey millimetreSurvey(std::size_t count, double spanMetres) {
    MillimetreSurvey survey;
    const auto span = static_cast<std::int32_t>(spanMetres / MillimetreSurvey::kScale);
    std::uint64_t state = 0x9E3779B97F4A7C15u;
    const auto next = [&](std::int32_t bound) {
        state = state * 6364136223846793005u + 1442695040888963407u;
        return static_cast<std::int32_t>((state >> 33) % static_cast<std::uint64_t>(bound));
    };
    survey.stored.push_back({0, 0, 0});
    survey.stored.push_back({span, span, 500000});
    while (survey.stored.size() < count) {
        survey.stored.push_back({next(span), next(span), next(500000)});
    }
    glm::dvec3 min(std::numeric_limits<double>::infinity());
    glm::dvec3 max(-std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < count; ++i) {
        min = glm::min(min, survey.fileCoordinates(i));
        max = glm::max(max, survey.fileCoordinates(i));
    }
    constexpr std::uint16_t kHeaderSize = 227;
    constexpr std::uint16_t kRecordLength = 20;
    std::string& b = survey.bytes;
    b = "LASF";
    b.append(4, '\0');   // file source ID, global encoding
    b.append(16, '\0');  // project GUID
    b += '\x01';
    b += '\x02';
    b.append(64, '\0');  // system identifier, generating software
    test::appendBytes(b, std::uint16_t{1});
    test::appendBytes(b, std::uint16_t{2026});
    test::appendBytes(b, kHeaderSize);
    test::appendBytes(b, std::uint32_t{kHeaderSize});  // offset to the point data
    test::appendBytes(b, std::uint32_t{0});            // VLRs
    b += '\0';                                         // point format 0
    test::appendBytes(b, kRecordLength);
    test::appendBytes(b, static_cast<std::uint32_t>(count));
    test::appendBytes(b, static_cast<std::uint32_t>(count));  // first returns
    b.append(16, '\0');
    for (int axis = 0; axis < 3; ++axis) {
        test::appendBytes(b, MillimetreSurvey::kScale);
    }
    for (int axis = 0; axis < 3; ++axis) {
        test::appendBytes(b, survey.offset[axis]);
    }
    for (int axis = 0; axis < 3; ++axis) {
        test::appendBytes(b, max[axis]);
        test::appendBytes(b, min[axis]);
    }
    EXPECT_EQ(b.size(), kHeaderSize);
    for (std::size_t i = 0; i < count; ++i) {
        for (const std::int32_t value : survey.stored[i]) {
            test::appendBytes(b, value);
        }
        test::appendBytes(b, static_cast<std::uint16_t>(i % 4096));  // intensity
        test::appendBytes(b, std::uint8_t{0x09});                    // return 1 of 1
        test::appendBytes(b, std::uint8_t{2});                       // ground
        b.append(4, '\0');  // scan angle, user data, point source ID
    }
    return survey;
}

/// x, y and z of every point of a binary little-endian PLY or PCD file as subscan writes them,
/// read by this test from the formats' descriptions (not by subscan's readers, which keep
/// floats); `coordinateType` receives the type the header gives x.
std::vector<glm::dvec3> readCoordinates(const std::filesystem::path& path,
                                        std::string& coordinateType) {
    const std::string file = test::fileBytes(path);
    const bool ply = path.extension() == ".ply";
    const std::string end = ply ? "end_header\n" : "DATA binary\n";
    const std::size_t body = file.find(end);
    if (body == std::string::npos) {
        ADD_FAILURE() << path << " has no " << end;
        return {};
    }
    std::vector<std::string> names, types;
    std::vector<std::size_t> sizes;
    std::size_t count = 0;
    std::istringstream header(file.substr(0, body));
    for (std::string line; std::getline(header, line);) {
        std::istringstream words(line);
        std::string keyword;
        words >> keyword;
        if (ply && keyword == "property") {
            std::string type, name;
            words >> type >> name;
            types.push_back(type);
            names.push_back(name);
            sizes.push_back(type == "double" ? 8 : type == "float" || type == "uint" ? 4 : 1);
        } else if (ply && keyword == "element") {
            std::string element;
            words >> element >> count;
            if (element != "vertex") {
                break;  // subscan writes faces after the vertices only for meshes
            }
        } else if (!ply && keyword == "FIELDS") {
            for (std::string name; words >> name;) {
                names.push_back(name);
            }
        } else if (!ply && keyword == "SIZE") {
            for (std::size_t size = 0; words >> size;) {
                sizes.push_back(size);
            }
        } else if (!ply && keyword == "TYPE") {
            for (std::string type; words >> type;) {
                types.push_back(type);
            }
        } else if (!ply && keyword == "POINTS") {
            words >> count;
        }
    }
    std::size_t stride = 0;
    for (const std::size_t size : sizes) {
        stride += size;
    }
    EXPECT_GE(names.size(), 3u);
    EXPECT_EQ(std::vector<std::string>(names.begin(), names.begin() + 3),
              (std::vector<std::string>{"x", "y", "z"}));
    coordinateType = types.at(0) + " " + std::to_string(sizes.at(0));
    EXPECT_EQ(file.size(), body + end.size() + count * stride) << path;
    std::vector<glm::dvec3> coordinates(count);
    const char* data = file.data() + body + end.size();
    for (std::size_t i = 0; i < count; ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            const char* at = data + i * stride + static_cast<std::size_t>(axis) * sizes[0];
            if (sizes[0] == 8) {
                std::memcpy(&coordinates[i][axis], at, 8);
            } else {
                float value = 0.0f;
                std::memcpy(&value, at, 4);
                coordinates[i][axis] = value;
            }
        }
    }
    return coordinates;
}

TEST(ConvertCommandTest, ASurveyOf200KmKeepsItsMillimetresInEveryFormat) {
    // 200 km of millimetres: floats relative to the first point, then the centre, rounded them
    // by up to 12 mm in memory (7.7 mm at worst here), which PLY and PCD output kept in their
    // doubles (the outside hunt's 200 km survey). Each coordinate must come back to within half
    // the scale's step, which gives back the stored integer.
    const test::TempDir dir;
    const MillimetreSurvey survey = millimetreSurvey(3000, 200000.0);
    const auto input = dir.write("survey.las", survey.bytes);
    const double halfStep = 0.5 * MillimetreSurvey::kScale;
    // LAS and LAZ pass the records on: the same integers on the same grid, exactly.
    const std::unique_ptr<PointRecordSource> original = openPointRecordSource(input);
    std::vector<std::byte> originalRecords;
    while (original->read(originalRecords, 1024) > 0) {
    }
    for (const std::string name : {"survey.las", "survey.laz"}) {
        SCOPED_TRACE(name);
        const auto output = dir / ("out_" + name);
        convert(input.string(), output);
        const std::unique_ptr<PointRecordSource> written = openPointRecordSource(output);
        EXPECT_EQ(written->info().quantization, original->info().quantization);
        std::vector<std::byte> records;
        while (written->read(records, 1024) > 0) {
        }
        const std::size_t length = written->info().format.recordLength();
        ASSERT_EQ(records.size(), survey.stored.size() * length);
        for (std::size_t i = 0; i < survey.stored.size(); ++i) {
            std::array<std::int32_t, 3> xyz{};
            std::memcpy(xyz.data(), records.data() + i * length, sizeof xyz);
            ASSERT_EQ(xyz, survey.stored[i]) << "point " << i;
        }
    }
    // From the LAS and from the LAZ just written (its reader decompresses first).
    for (const auto& [from, name] : {std::pair{input, "survey.ply"}, std::pair{input, "survey.pcd"},
                                     std::pair{dir / "out_survey.laz", "from_laz.ply"},
                                     std::pair{dir / "out_survey.laz", "from_laz.pcd"}}) {
        SCOPED_TRACE(name);
        const auto output = dir / name;
        convert(from.string(), output);
        std::string type;
        const std::vector<glm::dvec3> coordinates = readCoordinates(output, type);
        ASSERT_EQ(coordinates.size(), survey.stored.size());
        EXPECT_TRUE(type == "double 8" || type == "F 8") << type;
        double worst = 0.0;
        std::size_t wrong = 0;
        for (std::size_t i = 0; i < coordinates.size(); ++i) {
            const glm::dvec3 error = glm::abs(coordinates[i] - survey.fileCoordinates(i));
            const double largest = std::max({error.x, error.y, error.z});
            worst = std::max(worst, largest);
            wrong += largest >= halfStep ? 1 : 0;
        }
        EXPECT_EQ(wrong, 0u) << "worst error " << worst << " m";
    }
    EXPECT_EQ(test::fileBytes(input), survey.bytes);  // the input is never written
}

TEST(ConvertCommandTest, DoublesOf200KmComeBackAsTheyWere) {
    // A PLY of double coordinates on no grid spanning 200 km: kept to a micrometre
    // (kDoubleCoordinateTolerance), where the floats in memory lost millimetres.
    const test::TempDir dir;
    std::string ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 500\nproperty double x\n"
        "property double y\nproperty double z\nend_header\n";
    std::vector<glm::dvec3> points;
    for (int i = 0; i < 500; ++i) {
        const double t = i / 499.0;
        points.emplace_back(400000.0 + 200000.0 * t + 1e-4 / 3.0 * i,
                            5000000.0 + 200000.0 * std::sqrt(t), 100.0 + std::sin(i));
        for (int axis = 0; axis < 3; ++axis) {
            test::appendBytes(ply, points.back()[axis]);
        }
    }
    const auto input = dir.write("doubles.ply", ply);
    for (const std::string name : {"out.ply", "out.pcd"}) {
        SCOPED_TRACE(name);
        convert(input.string(), dir / name);
        std::string type;
        const std::vector<glm::dvec3> coordinates = readCoordinates(dir / name, type);
        ASSERT_EQ(coordinates.size(), points.size());
        for (std::size_t i = 0; i < points.size(); ++i) {
            // Double sums of values about 5e6 round by 1e-9, the float residual finer still.
            ASSERT_LT(glm::length(coordinates[i] - points[i]), 1e-8) << "point " << i;
        }
    }
}

TEST(ConvertCommandTest, SixteenBitColourCutToEightIsNamed) {
    // 16-bit colour (a binary PLY's ushort, kept as such in LAZ) came out of PLY, PCD and XYZ
    // as 8 bits without a word (found by the outside hunt).
    const test::TempDir dir;
    std::string ply =
        "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
        "property float y\nproperty float z\nproperty ushort red\nproperty ushort green\n"
        "property ushort blue\nend_header\n";
    for (const auto& [x, color] :
         {std::pair{0.0f, std::array<std::uint16_t, 3>{1000, 40000, 65535}},
          std::pair{1.0f, std::array<std::uint16_t, 3>{300, 2, 7}}}) {
        for (const float coordinate : {x, 0.0f, 0.0f}) {
            ply.append(reinterpret_cast<const char*>(&coordinate), sizeof coordinate);
        }
        ply.append(reinterpret_cast<const char*>(color.data()), sizeof color);
    }
    const auto laz = dir / "rgb16.laz";
    convert(dir.write("rgb16.ply", ply).string(), laz);
    for (const std::string name : {"out.ply", "out.pcd", "out.xyz"}) {
        const auto output = dir / name;
        const test::CommandResult result =
            runSubscan({"convert", laz.string(), "-o", output.string()});
        ASSERT_EQ(result.exitCode, 0) << result.err;
        EXPECT_THAT(result.err, HasSubstr("warning: " + output.string() + ": " +
                                          (name == "out.ply"   ? "PLY"
                                           : name == "out.pcd" ? "PCD"
                                                               : "XYZ text") +
                                          " output is written with 8-bit colour, so the "
                                          "input's colour of more than 8 bits a channel is cut "
                                          "to 8 bits"));
    }
    // It said "16-bit" of every input, E57 colour of 12-bit limits too. A PCD's 16-bit
    // channels, as PDAL writes them, are named alike.
    const std::filesystem::path pcd = dir.write(
        "rgb16.pcd",
        "VERSION 0.7\nFIELDS x y z red green blue\nSIZE 4 4 4 2 2 2\nTYPE F F F U U U\n"
        "COUNT 1 1 1 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n0 0 0 1000 40000 7\n");
    const test::CommandResult fromPcd =
        runSubscan({"convert", pcd.string(), "-o", (dir / "from-pcd.ply").string()});
    ASSERT_EQ(fromPcd.exitCode, 0) << fromPcd.err;
    EXPECT_THAT(fromPcd.err, HasSubstr("the input's colour of more than 8 bits a channel"));
    EXPECT_THAT(fromPcd.err, ::testing::Not(HasSubstr("16-bit")));
    // Through LAS 1.2 and back the colour is 8-bit times 257: nothing more to cut.
    const auto las = dir / "rgb8.las";
    convert((dir / "out.ply").string(), las);
    const test::CommandResult again =
        runSubscan({"convert", las.string(), "-o", (dir / "again.ply").string()});
    EXPECT_THAT(again.err, ::testing::Not(HasSubstr("colour")));
}

TEST(ConvertCommandTest, IntensitiesLasCannotHoldAreNamed) {
    // Rounded and clamped to LAS's whole 0..65535 without a word, while LAZ's line said every
    // attribute was kept (found by the outside hunt).
    const test::TempDir dir;
    const auto input = dir.write("confidence.xyz", "x y z i\n0 0 0 0.25\n1 0 0 0.5\n0 1 0 1\n");
    for (const char* name : {"out.las", "out.laz"}) {
        const test::CommandResult result =
            runSubscan({"convert", input.string(), "-o", (dir / name).string()});
        ASSERT_EQ(result.exitCode, 0) << result.err;
        EXPECT_THAT(result.err, HasSubstr("intensities are not all whole numbers within "
                                          "0..65535, which LAS holds"))
            << name;
        EXPECT_THAT(result.out, ::testing::Not(HasSubstr("every attribute"))) << name;
    }
}

TEST(ConvertCommandTest, UnknownExtensionIsAUsageError) {
    const test::TempDir dir;
    const auto output = dir / "sphere.obj";
    const test::CommandResult result =
        runSubscan({"convert", "synthetic:sphere", "-o", output.string()});
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_THAT(result.err, HasSubstr(".ply, .las, .pcd, .xyz"));
    EXPECT_FALSE(std::filesystem::exists(output));
}

TEST(ConvertCommandTest, RefusesToWriteOverItsInput) {
    const test::TempDir dir;
    const auto input = dir / "in.ply";
    convert("synthetic:sphere", input);
    const std::string before = test::fileBytes(input);
    const auto link = dir / "link.ply";
    std::filesystem::create_hard_link(input, link);
    // The same path, another spelling of it, and a hard link to the file.
    for (const auto& output : {input, dir / "." / "in.ply", link}) {
        const test::CommandResult result =
            runSubscan({"convert", input.string(), "-o", output.string()});
        EXPECT_EQ(result.exitCode, 1) << output;
        EXPECT_EQ(test::lineCount(result.err), 1u) << result.err;
        EXPECT_THAT(result.err, HasSubstr("refusing to write"));
        EXPECT_EQ(test::fileBytes(input), before) << output;
    }
}

TEST(ConvertCommandTest, UnwritableDirectoryIsOneSentence) {
    const test::TempDir dir;
    const auto missing = dir / "missing" / "out.las";
    const test::CommandResult result =
        runSubscan({"convert", "synthetic:sphere", "-o", missing.string()});
    EXPECT_EQ(result.exitCode, 1);
    EXPECT_TRUE(result.out.empty()) << result.out;
    EXPECT_EQ(test::lineCount(result.err), 1u) << result.err;
    EXPECT_THAT(result.err, HasSubstr(missing.string() + ": cannot write"));
}

TEST(ConvertCommandTest, ReadOnlyDirectoryIsOneSentence) {
    const test::TempDir dir;
    const auto readOnly = dir / "read-only";
    std::filesystem::create_directory(readOnly);
    std::filesystem::permissions(
        readOnly, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    if (access(readOnly.c_str(), W_OK) == 0) {
        GTEST_SKIP() << "running as root: a read-only directory is writable, not tested";
    }
    const auto denied = readOnly / "out.pcd";
    const test::CommandResult refused =
        runSubscan({"convert", "synthetic:sphere", "-o", denied.string()});
    std::filesystem::permissions(readOnly, std::filesystem::perms::owner_all);
    EXPECT_EQ(refused.exitCode, 1);
    EXPECT_EQ(test::lineCount(refused.err), 1u) << refused.err;
    EXPECT_THAT(refused.err, HasSubstr(denied.string() + ": cannot write"));
    EXPECT_TRUE(std::filesystem::is_empty(readOnly));
}

}  // namespace
}  // namespace subscan
