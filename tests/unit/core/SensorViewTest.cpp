#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/glm.hpp>

#include "core/Error.h"
#include "core/SensorView.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

struct OrganisedScan {
    PointCloud cloud;
    OrganisedGrid grid;
};

/// A depth camera's cloud: the middle of every kept cell of a width x height image seen through
/// a pinhole (focal length `focal` pixels, principal point `principal` from the top-left
/// corner) at `eye`, turned by `sensorToFile` (columns: the sensor's x right, y down and z
/// forward axes in file coordinates), at depths between 1 and 4. About a third of the cells
/// have no measurement.
OrganisedScan depthCamera(const glm::dvec3& eye, const glm::dmat3& sensorToFile, double focal,
                          const glm::dvec2& principal, int width, int height) {
    std::mt19937 random(5);
    std::uniform_real_distribution<double> depth(1.0, 4.0);
    std::bernoulli_distribution missing(0.35);
    PointCloudBuilder builder({}, static_cast<std::size_t>(width * height));
    OrganisedScan scan;
    scan.grid.width = width;
    scan.grid.height = height;
    for (int v = 0; v < height; ++v) {
        for (int u = 0; u < width; ++u) {
            if (missing(random)) {
                continue;
            }
            const double z = depth(random);
            const glm::dvec3 sensor((u + 0.5 - principal.x) / focal * z,
                                    (v + 0.5 - principal.y) / focal * z, z);
            PointRecord record;
            record.position = eye + sensorToFile * sensor;
            builder.add(record);
            scan.grid.cellOfPoint.push_back(static_cast<std::uint32_t>(v * width + u));
        }
    }
    std::vector<std::string> warnings;
    scan.cloud = builder.finish(warnings);
    return scan;
}

/// Where `camera` draws the cloud's point i, in pixels from the top-left corner.
glm::dvec2 windowPosition(const Camera& camera, const PointCloud& cloud, std::size_t i) {
    const glm::dvec4 clip = camera.projection() * camera.viewFromCloud(cloud.origin) *
                            glm::dvec4(glm::dvec3(cloud.positions[i]), 1.0);
    return {(clip.x / clip.w + 1.0) * 0.5 * camera.width,
            (1.0 - clip.y / clip.w) * 0.5 * camera.height};
}

TEST(SensorViewTest, PinholeFitRecoversTheDepthCamera) {
    // A sensor far from the file's origin (UTM-like), turned about all three axes, with its
    // principal point off the middle as real ones are.
    const glm::dvec3 eye(512000.3, 4100000.7, 120.2);
    const glm::dmat3 turn =
        glm::dmat3(glm::rotate(glm::dmat4(1.0), 0.4, glm::normalize(glm::dvec3(1, -2, 0.5))));
    // A small image (160 x 120, fovy about 13°): a narrow view conditions the fit no better
    // than a real 640 x 480 one.
    constexpr double kFocal = 525.0;
    const glm::dvec2 principal(82.8, 57.4);
    const OrganisedScan scan = depthCamera(eye, turn, kFocal, principal, 160, 120);

    const PinholeFit fit = fitPinhole(scan.cloud, scan.grid);
    // Positions are floats about the cloud's origin (steps of ~2e-7 m over 4 m), so each point
    // is off its ray by ~1e-7 rad, ~5e-5 pixels; the fit of ~12,000 points averages that.
    EXPECT_LT(fit.rmsErrorPixels, 1e-3);
    EXPECT_NEAR(fit.focalX, kFocal, 1e-2);
    EXPECT_NEAR(fit.focalY, kFocal, 1e-2);
    EXPECT_NEAR(fit.principalPoint.x, principal.x, 1e-2);
    EXPECT_NEAR(fit.principalPoint.y, principal.y, 1e-2);
    EXPECT_LT(glm::length(fit.camera.eye() - eye), 1e-4);  // 0.1 mm at 4 m: 1e-2 px
    EXPECT_EQ(fit.camera.width, 160);
    EXPECT_EQ(fit.camera.height, 120);
    EXPECT_NEAR(fit.camera.fovyDegrees, glm::degrees(2.0 * std::atan(60.0 / kFocal)), 1e-4);
    // The camera as the renderer uses it (view, projection, principal offset) draws every
    // point in the middle of its own cell, and between the near and far planes.
    for (std::size_t i = 0; i < scan.cloud.size(); ++i) {
        const std::uint32_t cell = scan.grid.cellOfPoint[i];
        const glm::dvec2 expected(cell % 160 + 0.5, cell / 160 + 0.5);
        const glm::dvec2 drawn = windowPosition(fit.camera, scan.cloud, i);
        ASSERT_LT(glm::length(drawn - expected), 1e-2) << "point " << i;
        const double depth = -(fit.camera.viewFromCloud(scan.cloud.origin) *
                               glm::dvec4(glm::dvec3(scan.cloud.positions[i]), 1.0))
                                  .z;
        ASSERT_GT(depth, fit.camera.nearPlane);
        ASSERT_LT(depth, fit.camera.farPlane);
    }
}

TEST(SensorViewTest, AutoUpOfADepthCameraInItsOwnFrameIsNegativeY) {
    // In its own frame (x right, y down) the picture's up is -Y; turned so that its up is +Y
    // or +Z, or named, the axis is the usual one.
    const glm::dvec2 principal(40.0, 30.0);
    const OrganisedScan own = depthCamera({0, 0, 0}, glm::dmat3(1.0), 100.0, principal, 80, 60);
    EXPECT_EQ(upAxisForScan("auto", "pcd", own.cloud, own.grid), UpAxis::NegativeY);
    EXPECT_EQ(upAxisForScan("y", "pcd", own.cloud, own.grid), UpAxis::Y);
    EXPECT_EQ(upAxisForScan("auto", "pcd", own.cloud, {}), UpAxis::Y);  // no grid
    // Columns: the sensor's x, y (down) and z axes in file coordinates.
    const glm::dmat3 upright(glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(0, 0, -1));
    const OrganisedScan level = depthCamera({0, 0, 0}, upright, 100.0, principal, 80, 60);
    EXPECT_EQ(upAxisForScan("auto", "pcd", level.cloud, level.grid), UpAxis::Y);
    // Only -Y is taken from the camera: one whose picture points up along +Z keeps Y.
    const glm::dmat3 zUp(glm::dvec3(1, 0, 0), glm::dvec3(0, 0, -1), glm::dvec3(0, 1, 0));
    const OrganisedScan lidar = depthCamera({0, 0, 0}, zUp, 100.0, principal, 80, 60);
    EXPECT_EQ(upAxisForScan("auto", "pcd", lidar.cloud, lidar.grid), UpAxis::Y);
    // A grid that is no pinhole image (here its cells shuffled) keeps the named axis.
    OrganisedScan shuffled = own;
    std::mt19937 random(3);
    std::shuffle(shuffled.grid.cellOfPoint.begin(), shuffled.grid.cellOfPoint.end(), random);
    EXPECT_EQ(upAxisForScan("auto", "pcd", shuffled.cloud, shuffled.grid), UpAxis::Y);
}

TEST(SensorViewTest, AScannersAngularGridIsNoPinholeImage) {
    // A terrestrial scanner's organised grid: columns of azimuth over 120°, rows of elevation;
    // straight lines bend in it, so no pinhole camera sends the points to their cells (by
    // several pixels at this size, more at a real scanner's thousands of columns).
    constexpr int kWidth = 600, kHeight = 200;
    PointCloudBuilder builder({}, kWidth * kHeight);
    OrganisedGrid grid{kWidth, kHeight, {}};
    for (int v = 0; v < kHeight; ++v) {
        for (int u = 0; u < kWidth; ++u) {
            const double azimuth = glm::radians(-60.0 + 120.0 * (u + 0.5) / kWidth);
            const double elevation = glm::radians(20.0 - 40.0 * (v + 0.5) / kHeight);
            const double range = 10.0 + 0.01 * ((u * 7 + v * 3) % 11);
            PointRecord record;
            record.position =
                range * glm::dvec3(std::sin(azimuth) * std::cos(elevation),
                                   std::cos(azimuth) * std::cos(elevation), std::sin(elevation));
            builder.add(record);
            grid.cellOfPoint.push_back(static_cast<std::uint32_t>(v * kWidth + u));
        }
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    EXPECT_GT(fitPinhole(cloud, grid).rmsErrorPixels, kPinholeToleranceRmsPixels);
}

TEST(SensorViewTest, TooFewPointsForACameraIsOneSentence) {
    const OrganisedScan scan =
        depthCamera(glm::dvec3(0.0), glm::dmat3(1.0), 100.0, {1.5, 1.0}, 3, 2);
    OrganisedScan few = scan;
    few.grid.cellOfPoint.resize(std::min<std::size_t>(5, scan.grid.cellOfPoint.size()));
    try {
        fitPinhole(few.cloud, few.grid);
        FAIL() << "fitted a camera to 5 points";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), HasSubstr("at least 6"));
    }
}

TEST(SensorViewTest, SensorCameraLooksFromTheSensorAtThePoints) {
    // A block of points 40 x 30 x 10 m and a station beside it, 1.5 m above the ground.
    PointCloudBuilder builder({}, 1000);
    std::mt19937 random(3);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int i = 0; i < 1000; ++i) {
        PointRecord record;
        record.position = glm::dvec3(300000.0, 5000000.0, 50.0) +
                          glm::dvec3(40.0 * unit(random), 30.0 * unit(random), 10.0 * unit(random));
        builder.add(record);
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const SensorPose station{{300000.0 - 15.0, 5000000.0 + 12.0, 51.5}, "the test's station"};
    const Camera camera = sensorCamera(cloud, station, UpAxis::Z, 320, 200, 60.0);
    EXPECT_LT(glm::length(camera.eye() - station.position), 1e-6);
    EXPECT_EQ(camera.width, 320);
    EXPECT_DOUBLE_EQ(camera.fovyDegrees, 60.0);
    // The middle of the points' framing box is straight ahead: the picture's middle.
    const glm::dvec4 clip =
        camera.projection() * camera.view * glm::dvec4(framingBounds(cloud).center(), 1.0);
    EXPECT_NEAR(clip.x / clip.w, 0.0, 1e-9);
    EXPECT_NEAR(clip.y / clip.w, 0.0, 1e-9);
    // Upright: the up axis points up in the picture.
    const glm::dvec3 upInView = glm::dmat3(camera.view) * glm::dvec3(0, 0, 1);
    EXPECT_GT(upInView.y, 0.9);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const double depth =
            -(camera.viewFromCloud(cloud.origin) * glm::dvec4(glm::dvec3(cloud.positions[i]), 1.0))
                 .z;
        ASSERT_GT(depth, camera.nearPlane);
        ASSERT_LT(depth, camera.farPlane);
    }

    // A pose that has nothing to do with the points (a default VIEWPOINT at the origin of UTM
    // data): one sentence naming where it came from, never a picture of a speck.
    const SensorPose unrelated{glm::dvec3(0.0), "the PCD default VIEWPOINT"};
    try {
        sensorCamera(cloud, unrelated, UpAxis::Z, 320, 200, 60.0);
        FAIL() << "accepted a sensor 5,000 km from the points";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), HasSubstr("the PCD default VIEWPOINT"));
        EXPECT_THAT(error.what(), HasSubstr("--sensor X,Y,Z"));
    }
}

TEST(SensorViewTest, ASensorNearlyStraightAboveItsPointsTurnsNoPicture) {
    // Within 0.81° of straight above the picture's up used to be replaced by a fixed axis: a
    // sensor moved by a hair across that angle turned the picture (an airborne pass overhead).
    PointCloudBuilder builder({}, 400);
    for (int i = 0; i < 400; ++i) {
        PointRecord record;
        record.position = glm::dvec3(i % 20, i / 20, 0.05 * (i % 7));
        builder.add(record);
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const glm::dvec3 middle = framingBounds(cloud).center();
    for (const double bearing : {0.0, 1.0, 2.5, -2.0}) {
        const glm::dvec3 away(std::cos(bearing), std::sin(bearing), 0.0);
        // 100 m up, 1.2 m and 1.6 m aside: 0.69° and 0.92° from the vertical, either side.
        const Camera inside = sensorCamera(
            cloud, {middle + glm::dvec3(0, 0, 100) + 1.2 * away, "inside"}, UpAxis::Z, 64, 48, 40);
        const Camera outside = sensorCamera(
            cloud, {middle + glm::dvec3(0, 0, 100) + 1.6 * away, "outside"}, UpAxis::Z, 64, 48, 40);
        // The picture's up axis in world space; 0.23° of tilt apart moves it by about 0.004.
        const glm::dvec3 upInside(inside.view[0][1], inside.view[1][1], inside.view[2][1]);
        const glm::dvec3 upOutside(outside.view[0][1], outside.view[1][1], outside.view[2][1]);
        EXPECT_LT(glm::length(upInside - upOutside), 0.01) << bearing;
    }
}

TEST(SensorViewTest, AStationAmidItsPointsLooksLevelTowardsTheirMiddle) {
    // Ground 60 x 60 m around the station (1.5 m above it, Y up), a 30 m tower straight above
    // the station's feet raising the framing box's middle to 15 m, and a building 45 m east.
    PointCloudBuilder builder({}, 4000);
    const auto add = [&](const glm::dvec3& position) {
        PointRecord record;
        record.position = position;
        builder.add(record);
    };
    for (int i = 0; i < 60; ++i) {
        for (int j = 0; j < 60; ++j) {
            add({i - 30.0, 0.0, j - 30.0});
        }
    }
    for (int k = 0; k <= 30; ++k) {
        add({0.0, k, 0.0});
    }
    for (int k = 0; k < 10; ++k) {
        for (int j = 0; j < 10; ++j) {
            add({45.0, k, j - 5.0});  // the building's wall
        }
    }
    std::vector<std::string> warnings;
    const PointCloud cloud = builder.finish(warnings);
    const SensorPose station{{0.0, 1.5, 0.0}, "the test's station"};
    const Camera camera = sensorCamera(cloud, station, UpAxis::Y, 320, 200, 60.0);
    // Level: the view direction has no vertical part; it faces the middle's azimuth (+X here,
    // where the building widens the box).
    const glm::dvec3 forward = -glm::dvec3(glm::transpose(glm::dmat3(camera.view))[2]);
    EXPECT_NEAR(forward.y, 0.0, 1e-9);
    const glm::dvec3 middle = framingBounds(cloud).center();
    const glm::dvec3 level = glm::normalize(glm::dvec3(middle.x, 0.0, middle.z));
    EXPECT_NEAR(glm::dot(forward, level), 1.0, 1e-9);
}

}  // namespace
}  // namespace subscan
