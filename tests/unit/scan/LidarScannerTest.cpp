// The virtual scanner's LiDAR modes (one terrestrial station, one airborne strip) and the
// outdoor scene they are meant for.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <set>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "scan/Scene.h"
#include "scan/SyntheticScenes.h"
#include "scan/VirtualScanner.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;
using Mode = ScannerSettings::Mode;

constexpr glm::dvec3 kUp{0.0, 1.0, 0.0};
constexpr glm::dvec3 kAlongZ{0.0, 0.0, 1.0};

/// A station of 1-degree steps in both directions, without noise.
ScannerSettings coarseStation() {
    ScannerSettings settings;
    settings.mode = Mode::Station;
    settings.station.azimuthSteps = 360;
    settings.station.elevationSteps = 150;  // -60 to +90 degrees
    return settings;
}

glm::dvec3 worldPosition(const PointCloud& cloud, std::size_t i) {
    return cloud.origin + glm::dvec3(cloud.positions[i]);
}

TEST(LidarScannerTest, StationRaysAreEqualAngularStepsApart) {
    // From the middle of the unit sphere every ray hits at range 1, so each point is its ray's
    // direction and the cloud is the full grid, profile by profile.
    const auto sphere = makeBuiltInScene("sphere");
    ScannerSettings settings = coarseStation();
    settings.station.position = glm::dvec3(0.0);
    const PointCloud cloud = scanScene(*sphere, settings);
    const std::size_t profile = 150;
    ASSERT_EQ(cloud.size(), 360u * profile);
    const double step = glm::radians(1.0);
    // Float positions on a unit sphere are rounded by ~6e-8 per coordinate; 1e-6 is well above
    // that and far below the 0.017 of a chord.
    constexpr double kTolerance = 1e-6;
    for (std::size_t azimuth = 0; azimuth < 360; azimuth += 37) {
        const std::size_t first = azimuth * profile;
        EXPECT_NEAR(std::asin(worldPosition(cloud, first).y), glm::radians(-60.0) + 0.5 * step,
                    kTolerance);
        for (std::size_t k = first; k + 1 < first + profile; ++k) {
            // Along a profile, neighbours are one elevation step apart: a chord of 2 sin(step/2).
            EXPECT_NEAR(glm::length(worldPosition(cloud, k + 1) - worldPosition(cloud, k)),
                        2.0 * std::sin(0.5 * step), kTolerance);
        }
        // Across profiles, at elevation e the azimuth step spans a chord of 2 cos(e) sin(step/2).
        const std::size_t next = ((azimuth + 1) % 360) * profile + 75;
        const double elevation = std::asin(worldPosition(cloud, first + 75).y);
        EXPECT_NEAR(glm::length(worldPosition(cloud, next) - worldPosition(cloud, first + 75)),
                    2.0 * std::cos(elevation) * std::sin(0.5 * step), kTolerance);
    }
}

TEST(LidarScannerTest, StationSpacingOnTheGroundGrowsWithRange) {
    // The outdoor scene's ground is the plane y = 0 and the default station stands 1.5 m above
    // the middle; looking along +X nothing stands in the way to the ground's edge at x = 30.
    const auto scene = makeBuiltInScene("outdoor");
    ScannerSettings settings = coarseStation();
    settings.station.azimuthSteps = 720;  // 0.5 degrees
    settings.station.elevationSteps = 300;
    const double step = glm::radians(0.5);
    const glm::dvec3 station = stationPosition(*scene, settings.station);
    ASSERT_NEAR(station.y, 1.5, 1e-9);  // the ground below the middle is at y = 0 exactly
    const PointCloud cloud = scanScene(*scene, settings);

    // The profile at azimuth 90 degrees lies in the plane z = 0 (up to cos(pi/2) ~ 6e-17).
    std::vector<double> alongX;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec3 p = worldPosition(cloud, i);
        if (std::abs(p.z) < 1e-4 && p.x > 0.0 && std::abs(p.y) < 1e-4) {
            alongX.push_back(p.x);
        }
    }
    std::sort(alongX.begin(), alongX.end());
    ASSERT_GT(alongX.size(), 20u);
    for (std::size_t k = 0; k < alongX.size(); ++k) {
        // Ray k of the profile meets the ground where tan(-elevation) = 1.5 / x: the exact
        // positions of equal elevation steps from -60 degrees (float storage: ~4e-6 m at 30 m).
        const double elevation = glm::radians(-60.0) + (static_cast<double>(k) + 0.5) * step;
        EXPECT_NEAR(alongX[k], 1.5 / std::tan(-elevation), 1e-5) << "ray " << k;
    }
    // Radially the gap grows with the square of the range (range^2 step / height): the far
    // rings are many times sparser than the near ones (the 20x of real stations).
    const double nearGap = alongX[1] - alongX[0];
    const double farGap = alongX.back() - alongX[alongX.size() - 2];
    EXPECT_GT(farGap / nearGap, 20.0);

    // Across the rings, neighbours on one ring at horizontal distance d are d x the azimuth
    // step apart (the chord 2 d sin(step / 2) differs from d step by step^2 / 24 ~ 3e-6).
    const double ringDistance = alongX[alongX.size() / 2];
    std::vector<glm::dvec3> ring;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec3 p = worldPosition(cloud, i);
        if (std::abs(p.y) < 1e-4 && p.x > 0.0 && std::abs(p.z) < 0.05 * ringDistance &&
            std::abs(std::hypot(p.x, p.z) - ringDistance) < 1e-4) {
            ring.push_back(p);
        }
    }
    std::sort(ring.begin(), ring.end(), [](const auto& a, const auto& b) { return a.z < b.z; });
    ASSERT_GE(ring.size(), 3u);
    for (std::size_t k = 0; k + 1 < ring.size(); ++k) {
        // Relative 1e-4: float storage (~4e-6 m) on gaps of centimetres and more.
        EXPECT_NEAR(glm::length(ring[k + 1] - ring[k]) / (ringDistance * step), 1.0, 1e-4);
    }
}

TEST(LidarScannerTest, StationSeesNothingBehindTheGardenWall) {
    const auto scene = makeBuiltInScene("outdoor");
    ScannerSettings settings = coarseStation();
    settings.station.azimuthSteps = 720;
    settings.station.elevationSteps = 300;
    const PointCloud cloud = scanScene(*scene, settings);
    // The wall stands at z = 7.94..8.06 for |x| <= 5, 2.5 m high, and the station's eye is
    // 1.5 m high at the origin: every line from it to a point with |x| <= 4, z in [8.2, 16] and
    // y <= 2.4 crosses z = 8 at |x| < 5 and below 2.5 m. A car stands there, hidden.
    std::size_t behind = 0, onWallFront = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec3 p = worldPosition(cloud, i);
        behind += std::abs(p.x) <= 4.0 && p.z >= 8.2 && p.z <= 16.0 && p.y <= 2.4;
        // The front face (z = 7.94, 1e-4 for float storage).
        onWallFront += std::abs(p.z - 7.94) < 1e-4 && std::abs(p.x) < 5.0;
    }
    EXPECT_EQ(behind, 0u);
    EXPECT_GT(onWallFront, 100u);
    // The same from the sampling test the evaluation uses: the hidden car's top is not, the
    // wall's front is.
    EXPECT_FALSE(scannerCanSample(*scene, settings, glm::dvec3(0.0, 1.5, 12.0), kUp));
    EXPECT_TRUE(scannerCanSample(*scene, settings, glm::dvec3(1.0, 1.0, 7.94), -kAlongZ));
    // Straight below the station is out of the -60 degree elevation range.
    EXPECT_FALSE(scannerCanSample(*scene, settings, glm::dvec3(0.1, 0.0, 0.1), kUp));
}

TEST(LidarScannerTest, StationMaxRangeDropsFarSurfaces) {
    const auto scene = makeBuiltInScene("outdoor");
    ScannerSettings settings = coarseStation();
    settings.station.maxRange = 10.0;
    const PointCloud cloud = scanScene(*scene, settings);
    const glm::dvec3 station = stationPosition(*scene, settings.station);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        // Float storage adds ~4e-6 m at most.
        ASSERT_LT(glm::length(worldPosition(cloud, i) - station), 10.0 + 1e-4);
    }
    EXPECT_FALSE(scannerCanSample(*scene, settings, glm::dvec3(20.0, 0.0, 0.0), kUp));
}

TEST(LidarScannerTest, AirbornePointsLieInTheSwathOnEvenlySpacedLines) {
    const auto scene = makeBuiltInScene("outdoor");
    ScannerSettings settings;
    settings.mode = Mode::Airborne;
    settings.airborne.lineSpacing = 1.0;
    settings.airborne.pointsPerLine = 100;
    const PointCloud cloud = scanScene(*scene, settings);
    const Bounds bounds = scene->bounds();
    const double sensorY = bounds.min.y + settings.airborne.altitude;
    const double halfField = glm::radians(0.5 * settings.airborne.fieldOfViewDegrees);
    std::set<long> lines;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec3 p = worldPosition(cloud, i);
        // Within the fan of its scan line (1e-4 m: float storage).
        ASSERT_LE(std::abs(p.z - bounds.center().z), (sensorY - p.y) * std::tan(halfField) + 1e-4);
        // Scan lines are vertical planes x = const; millimetres tell them apart.
        lines.insert(std::lround(p.x * 1000.0));
    }
    // 60 m of ground at 1 m spacing: 60 lines, 1 m apart, centred on the ground.
    ASSERT_EQ(lines.size(), 60u);
    long previous = *lines.begin();
    EXPECT_EQ(previous, -29500);
    for (auto it = std::next(lines.begin()); it != lines.end(); ++it) {
        EXPECT_EQ(*it - previous, 1000);
        previous = *it;
    }
    // A wall facing along the track is parallel to the scan planes: no line crosses it. One
    // facing across the track is crossed by every line over it.
    const glm::dvec3 alongX(1.0, 0.0, 0.0);
    EXPECT_FALSE(scannerCanSample(*scene, settings, glm::dvec3(-7.0, 4.0, -11.0), alongX));
    EXPECT_TRUE(scannerCanSample(*scene, settings, glm::dvec3(-13.0, 4.0, -7.0), kAlongZ));
}

TEST(LidarScannerTest, LidarSourcesHaveExactlyTheAskedPointCount) {
    const SyntheticSource station = makeSyntheticSource("outdoor-station?points=5000");
    EXPECT_EQ(station.points.size(), 5000u);
    EXPECT_EQ(station.scanner.mode, Mode::Station);
    ASSERT_TRUE(station.scanner.station.position.has_value());
    EXPECT_EQ(makeSyntheticScene("outdoor-airborne?points=4000").size(), 4000u);
    try {
        makeSyntheticScene("outdoor-boat");
        FAIL() << "no error";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), HasSubstr("outdoor-station, outdoor-airborne"));
    }
}

TEST(LidarScannerTest, ModeSettingsRoundTripThroughJsonAndAreValidated) {
    ScannerSettings settings;
    settings.mode = Mode::Station;
    settings.station.position = glm::dvec3(1.0, 2.0, 3.0);
    settings.station.azimuthSteps = 1000;
    settings.station.maxRange = 50.0;
    settings.airborne.altitude = 120.0;
    settings.airborne.pointsPerLine = 77;
    const nlohmann::json json = settings;
    EXPECT_EQ(json["mode"], "station");
    EXPECT_EQ(json.get<ScannerSettings>(), settings);

    auto error = [](const nlohmann::json& bad) {
        return test::errorMessage([&] { bad.get<ScannerSettings>(); });
    };
    EXPECT_THAT(error({{"mode", "drone"}}), HasSubstr("'mode' is 'drone'"));
    EXPECT_THAT(error({{"station", {{"azimuth_steps", 0}}}}), HasSubstr("azimuth steps"));
    EXPECT_THAT(error({{"station", {{"min_elevation_deg", 10}, {"max_elevation_deg", 0}}}}),
                HasSubstr("elevation range"));
    EXPECT_THAT(error({{"station", {{"wobble", 1}}}}), HasSubstr("'station.wobble'"));
    EXPECT_THAT(error({{"airborne", {{"altitude", -5}}}}), HasSubstr("flight altitude"));
    EXPECT_THAT(error({{"airborne", {{"field_of_view_deg", 180}}}}), HasSubstr("field of view"));
    EXPECT_THAT(error({{"airborne", {{"line_spacing", "wide"}}}}), HasSubstr("wrong type"));
    for (const std::string& message :
         {error({{"mode", "drone"}}), error({{"airborne", {{"altitude", -5}}}})}) {
        EXPECT_NE(message.back(), '.');  // one sentence without a trailing period
    }
}

}  // namespace
}  // namespace subscan
