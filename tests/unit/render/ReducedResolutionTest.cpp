// The reduced-resolution camera and the Auto choice (RasterSettings::resolution), without GL.
#include <random>

#include <gtest/gtest.h>
#include <glm/vec4.hpp>

#include "render/ReducedResolution.h"

namespace subscan {
namespace {

/// Where `camera` images a view-space point: pixel units, row 0 at the top, centres at .5.
glm::dvec2 imagePosition(const Camera& camera, const glm::dvec3& view) {
    const glm::dvec4 clip = camera.projection() * glm::dvec4(view, 1.0);
    const glm::dvec2 ndc = glm::dvec2(clip) / clip.w;
    return {0.5 * (ndc.x + 1.0) * camera.width, 0.5 * (1.0 - ndc.y) * camera.height};
}

TEST(ReducedResolutionTest, ReducedCameraSeesEveryPointWhereReducedPositionSays) {
    std::mt19937 random(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    // Even and odd sizes: an odd side makes the reduced image reach past the output.
    for (const glm::ivec2 size : {glm::ivec2(1920, 1080), glm::ivec2(161, 97), glm::ivec2(7, 5)}) {
        Camera output;
        output.width = size.x;
        output.height = size.y;
        output.fovyDegrees = 50.0;
        const Camera reduced = reducedCamera(output, 2);
        EXPECT_EQ(reduced.width, (size.x + 1) / 2);
        EXPECT_EQ(reduced.height, (size.y + 1) / 2);
        // Exact in theory; the field of view goes through atan, degrees, radians and tan, a few
        // ulps (measured 4.4e-16 at f = 5.4, 0 at f = 104 and 1158).
        EXPECT_NEAR(reduced.focalLengthPixels(), 0.5 * output.focalLengthPixels(),
                    1e-12 * output.focalLengthPixels());
        for (int i = 0; i < 100; ++i) {
            const double depth = 1.0 + 10.0 * (unit(random) + 1.0);
            const glm::dvec3 view(unit(random) * depth, unit(random) * depth, -depth);
            const glm::dvec2 expected = imagePosition(reduced, view);
            const glm::dvec2 mapped =
                reducedPosition(output, reduced, 2, imagePosition(output, view));
            // Double precision through two projections: measured at most 5.7e-14 pixels, under
            // an ulp of coordinates up to ~2000 (2.3e-13); 1e-11 leaves some 40 ulps.
            EXPECT_NEAR(mapped.x, expected.x, 1e-11);
            EXPECT_NEAR(mapped.y, expected.y, 1e-11);
        }
    }
}

/// A square grid of `side` x `side` points `spacing` apart in the plane z = 0.
PointCloud grid(int side, double spacing) {
    PointCloud cloud;
    for (int y = 0; y < side; ++y) {
        for (int x = 0; x < side; ++x) {
            const glm::dvec3 p((x - side / 2) * spacing, (y - side / 2) * spacing, 0.0);
            cloud.positions.push_back(glm::vec3(p));
            cloud.bounds.add(p);
        }
    }
    return cloud;
}

/// Looking at the grid's face from `distance`, 1920x1080, 45 degrees: f = 1303.8 pixels.
Camera facing(const PointCloud& cloud, double distance) {
    return orbitCamera(cloud.bounds, {0.0, 0.0, distance, UpAxis::Y}, 1920, 1080, 45.0);
}

TEST(ReducedResolutionTest, FullAndHalfAreWhatTheySay) {
    const PointCloud cloud = grid(100, 0.01);
    const ResolutionChooser chooser(cloud);
    for (const double distance : {1.0, 100.0}) {
        EXPECT_EQ(chooser.divisor(Resolution::Full, facing(cloud, distance), {}, 0.01, false), 1);
        EXPECT_EQ(chooser.divisor(Resolution::Half, facing(cloud, distance), {}, 0.01, false), 2);
    }
}

TEST(ReducedResolutionTest, AutoHalvesOnlyWhilePointsAreFourPixelsApartOrMore) {
    const PointCloud cloud = grid(100, 0.01);
    const ResolutionChooser chooser(cloud);
    const double focal = facing(cloud, 1.0).focalLengthPixels();
    // Distances where the grid's points are 4.4 and 3.6 pixels apart (f * h / z).
    const double sparse = focal * 0.01 / 4.4;
    const double dense = focal * 0.01 / 3.6;
    EXPECT_EQ(chooser.divisor(Resolution::Auto, facing(cloud, sparse), {}, 0.01, false), 2);
    EXPECT_EQ(chooser.divisor(Resolution::Auto, facing(cloud, dense), {}, 0.01, false), 1);
    // A close-up where only part of the grid is in view still counts only that part.
    EXPECT_EQ(chooser.divisor(Resolution::Auto, facing(cloud, 0.2), {}, 0.01, false), 2);
}

TEST(ReducedResolutionTest, AutoKeepsFullResolutionWithoutEvidence) {
    const PointCloud cloud = grid(100, 0.01);
    const ResolutionChooser chooser(cloud);
    // The eye of a close-up turned around (view = rotation of 180 degrees about y, then the
    // eye at z = 0.5): the grid is behind it.
    Camera away = facing(cloud, 0.5);
    away.view = glm::dmat4(-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0.5, 1);
    EXPECT_EQ(chooser.divisor(Resolution::Auto, away, {}, 0.01, false), 1);
    // An empty cloud, and a few points only.
    EXPECT_EQ(ResolutionChooser(PointCloud{}).divisor(Resolution::Auto, away, {}, 0.01, false), 1);
    const PointCloud few = grid(5, 0.01);
    EXPECT_EQ(ResolutionChooser(few).divisor(Resolution::Auto, facing(few, 0.1), {}, 0.01, false),
              1);
}

TEST(ReducedResolutionTest, AutoUsesEachPointsLocalSpacingOnScreen) {
    const PointCloud cloud = grid(100, 0.01);
    const double focal = facing(cloud, 1.0).focalLengthPixels();
    // Where h puts the points 3.6 pixels apart: full resolution on h alone.
    const Camera dense = facing(cloud, focal * 0.01 / 3.6);
    ResolutionChooser chooser(cloud);
    ASSERT_EQ(chooser.divisor(Resolution::Auto, dense, {}, 0.01, true), 1);  // none given yet
    // Twice h everywhere: 7.2 pixels apart, half resolution; unless told to use h alone.
    chooser.setLocalSpacing(std::vector<glm::vec4>(cloud.size(), glm::vec4(0, 0, 0, 2)));
    EXPECT_EQ(chooser.divisor(Resolution::Auto, dense, {}, 0.01, true), 2);
    EXPECT_EQ(chooser.divisor(Resolution::Auto, dense, {}, 0.01, false), 1);
    // Lines 3 h apart across y, seen face-on: the projected across vector decides (10.8 px)...
    chooser.setLocalSpacing(std::vector<glm::vec4>(cloud.size(), glm::vec4(0, 3, 0, 1)));
    EXPECT_EQ(chooser.divisor(Resolution::Auto, dense, {}, 0.01, true), 2);
    // ...and seen end-on (the vector along the view direction, at the image's centre) it
    // counts for nothing: the points are 3.6 pixels apart.
    chooser.setLocalSpacing(std::vector<glm::vec4>(cloud.size(), glm::vec4(0, 0, 3, 1)));
    EXPECT_EQ(chooser.divisor(Resolution::Auto, dense, {}, 0.01, true), 1);
}

}  // namespace
}  // namespace subscan
