#include <cmath>
#include <random>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "core/Error.h"
#include "scan/Marble.h"
#include "scan/Scene.h"
#include "scan/SignedDistanceScene.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

double sceneSize(const Scene& scene) {
    return glm::length(scene.bounds().extent());
}

glm::dvec3 randomUnitVector(std::mt19937_64& random) {
    std::normal_distribution<double> normal;
    return glm::normalize(glm::dvec3(normal(random), normal(random), normal(random)));
}

/// Rays from a sphere of twice the bounding radius towards random points of the bounds, so
/// most of them hit and they come from every side.
std::vector<Ray> raysTowards(const Scene& scene, int count, std::uint64_t seed) {
    std::mt19937_64 random(seed);
    const Bounds bounds = scene.bounds();
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<Ray> rays;
    for (int i = 0; i < count; ++i) {
        const glm::dvec3 origin = bounds.center() + sceneSize(scene) * randomUnitVector(random);
        const glm::dvec3 target =
            bounds.min + bounds.extent() * glm::dvec3(unit(random), unit(random), unit(random));
        rays.push_back({origin, glm::normalize(target - origin)});
    }
    return rays;
}

class BuiltInSceneTest : public ::testing::TestWithParam<std::string> {};

TEST_P(BuiltInSceneTest, HitsLieOnTheSurfaceWithUnitNormalsFacingTheRay) {
    const auto scene = makeBuiltInScene(GetParam());
    const double size = sceneSize(*scene);
    int hits = 0;
    for (const Ray& ray : raysTowards(*scene, 2000, 1)) {
        const auto hit = scene->intersect(ray, 10.0 * size);
        if (!hit) {
            continue;
        }
        ++hits;
        const glm::dvec3 point = ray.origin + hit->distance * ray.direction;
        // Refinement stops at a bracket of 1e-11 of the size; 1e-10 leaves room for the
        // rounding of the point itself.
        EXPECT_LE(scene->surfaceDistance(point), 1e-10 * size);
        EXPECT_NEAR(glm::length(hit->normal), 1.0, 1e-12);  // normalised in double
        EXPECT_LE(glm::dot(hit->normal, ray.direction), 0.0);
        for (int c = 0; c < 3; ++c) {
            EXPECT_GE(hit->albedo[c], 0.0f);
            EXPECT_LE(hit->albedo[c], 1.0f);
        }
    }
    EXPECT_GT(hits, 500);  // rays aim into the bounds, which every scene fills substantially
}

TEST_P(BuiltInSceneTest, NothingIsSkippedBeforeTheFirstHit) {
    const auto scene = makeBuiltInScene(GetParam());
    const double size = sceneSize(*scene);
    // Samples every 1e-3 of the size (0.3 mm on the sculpture, whose thinnest part is 4 mm)
    // must all be off the solid before the reported hit: a sample inside would be a missed
    // surface in front of it.
    const double step = 1e-3 * size;
    for (const Ray& ray : raysTowards(*scene, 300, 2)) {
        const auto hit = scene->intersect(ray, 10.0 * size);
        const double end = hit ? hit->distance - step : 10.0 * size;
        for (double t = 0.0; t < end; t += step) {
            const glm::dvec3 p = ray.origin + t * ray.direction;
            const auto inside = scene->intersect({p, ray.direction}, step);
            // A hit within one step of a sample on the way means a surface was crossed.
            ASSERT_FALSE(inside.has_value())
                << GetParam() << ": surface at " << t + inside->distance << " before the hit at "
                << (hit ? hit->distance : -1.0);
        }
    }
}

TEST_P(BuiltInSceneTest, SurfaceDistanceNeverExceedsTheDistanceToAHit) {
    const auto scene = makeBuiltInScene(GetParam());
    const double size = sceneSize(*scene);
    std::mt19937_64 random(3);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const Bounds bounds = scene->bounds();
    for (int i = 0; i < 200; ++i) {
        const glm::dvec3 p =
            bounds.min + bounds.extent() * glm::dvec3(unit(random), unit(random), unit(random));
        const double bound = scene->surfaceDistance(p);
        for (int j = 0; j < 20; ++j) {
            const auto hit = scene->intersect({p, randomUnitVector(random)}, 10.0 * size);
            if (hit) {
                // Every surface point reached is at least as far as the distance (or its lower
                // bound); 1e-10 of the size covers the hit's own tolerance.
                EXPECT_LE(bound, hit->distance + 1e-10 * size);
            }
        }
    }
}

TEST_P(BuiltInSceneTest, MaxDistanceCutsTheRay) {
    const auto scene = makeBuiltInScene(GetParam());
    const double size = sceneSize(*scene);
    for (const Ray& ray : raysTowards(*scene, 100, 4)) {
        const auto hit = scene->intersect(ray, 10.0 * size);
        if (hit) {
            EXPECT_FALSE(scene->intersect(ray, 0.999 * hit->distance).has_value());
        }
    }
}

INSTANTIATE_TEST_SUITE_P(AllScenes, BuiltInSceneTest,
                         ::testing::Values("sphere", "torus", "box-with-hole", "sculpture",
                                           "outdoor"),
                         [](const auto& testParam) {
                             std::string name = testParam.param;
                             std::erase(name, '-');
                             return name;
                         });

TEST(BuiltInScenesTest, UnknownNameListsTheScenes) {
    try {
        makeBuiltInScene("teapot");
        FAIL() << "no error";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), HasSubstr("no built-in scene 'teapot'"));
        EXPECT_THAT(error.what(), HasSubstr("sphere, torus, box-with-hole, sculpture, outdoor"));
    }
    EXPECT_EQ(builtInSceneNames().size(), 5u);
}

TEST(BuiltInScenesTest, SphereIsTheUnitSphereInClosedForm) {
    const auto sphere = makeBuiltInScene("sphere");
    const auto front = sphere->intersect({{0.0, 0.0, 5.0}, {0.0, 0.0, -1.0}}, 100.0);
    ASSERT_TRUE(front.has_value());
    EXPECT_DOUBLE_EQ(front->distance, 4.0);
    EXPECT_EQ(front->normal, glm::dvec3(0.0, 0.0, 1.0));
    // From inside, the ray meets the far side; its normal is turned towards the ray.
    const auto inside = sphere->intersect({{0.0, 0.5, 0.0}, {0.0, 1.0, 0.0}}, 100.0);
    ASSERT_TRUE(inside.has_value());
    EXPECT_DOUBLE_EQ(inside->distance, 0.5);
    EXPECT_EQ(inside->normal, glm::dvec3(0.0, -1.0, 0.0));
    EXPECT_FALSE(sphere->intersect({{0.0, 1.5, 5.0}, {0.0, 0.0, -1.0}}, 100.0).has_value());
    EXPECT_FALSE(sphere->intersect({{0.0, 0.0, 5.0}, {0.0, 0.0, 1.0}}, 100.0).has_value());
    EXPECT_DOUBLE_EQ(sphere->surfaceDistance({3.0, 0.0, 4.0}), 4.0);
    EXPECT_EQ(sphere->bounds().min, glm::dvec3(-1.0));
    EXPECT_EQ(sphere->bounds().max, glm::dvec3(1.0));
}

TEST(BuiltInScenesTest, TorusHitsItsTubeWhereExpected) {
    const auto torus = makeBuiltInScene("torus");
    // Straight down onto the top of the tube (centre circle radius 0.1, tube radius 0.035).
    const auto top = torus->intersect({{0.1, 1.0, 0.0}, {0.0, -1.0, 0.0}}, 10.0);
    ASSERT_TRUE(top.has_value());
    EXPECT_NEAR(top->distance, 1.0 - 0.035, 1e-12);  // 1e-11 of the size, the bracket width
    EXPECT_NEAR(top->normal.y, 1.0, 1e-12);
    // Down the middle of the hole there is nothing.
    EXPECT_FALSE(torus->intersect({{0.0, 1.0, 0.0}, {0.0, -1.0, 0.0}}, 10.0).has_value());
    // Sideways along X through the centre, the ray meets the outside of the tube first.
    const auto side = torus->intersect({{-1.0, 0.0, 0.0}, {1.0, 0.0, 0.0}}, 10.0);
    ASSERT_TRUE(side.has_value());
    EXPECT_NEAR(side->distance, 1.0 - 0.135, 1e-12);
}

TEST(BuiltInScenesTest, BoxWithHoleHasAThroughHoleAndAStep) {
    const auto box = makeBuiltInScene("box-with-hole");
    // Along Z through the hole's axis (x = -0.02, y = 0): straight through.
    EXPECT_FALSE(box->intersect({{-0.02, 0.0, 1.0}, {0.0, 0.0, -1.0}}, 10.0).has_value());
    // Beside the hole the front face is at z = 0.05.
    const auto face = box->intersect({{0.03, -0.04, 1.0}, {0.0, 0.0, -1.0}}, 10.0);
    ASSERT_TRUE(face.has_value());
    EXPECT_NEAR(face->distance, 0.95, 1e-12);
    EXPECT_NEAR(face->normal.z, 1.0, 1e-9);  // finite-difference gradient, accurate to ~1e-9
    // Down onto the step (x > 0.05): its floor is at y = 0.02, not the top at 0.06.
    const auto step = box->intersect({{0.08, 1.0, 0.0}, {0.0, -1.0, 0.0}}, 10.0);
    ASSERT_TRUE(step.has_value());
    EXPECT_NEAR(step->distance, 0.98, 1e-12);
}

TEST(BuiltInScenesTest, SculptureIsAbout30CentimetresTallStandingOnTheOrigin) {
    const auto sculpture = makeBuiltInScene("sculpture");
    const Bounds bounds = sculpture->bounds();
    EXPECT_NEAR(bounds.min.y, 0.0, 1e-12);
    // The top is the crest of the ring, tilted 35° about X around (0, 0.235, 0): its centre
    // circle (radius 0.095) rises to 0.095 sin 35° above the centre at z = -0.095 cos 35°, the
    // tube (radius 0.0028) adds its radius there: y = 0.29229. A ray down through the crest
    // hits it there (the hit is refined to ~1e-11; measured 0.2922900, and a grid of rays 0.5 mm
    // apart finds no higher point than 0.292284).
    const double tilt = glm::radians(35.0);
    const double crest = 0.235 + 0.095 * std::sin(tilt) + 0.0028;
    const auto crestHit =
        sculpture->intersect({{0.0, 1.0, -0.095 * std::cos(tilt)}, {0.0, -1.0, 0.0}}, 10.0);
    ASSERT_TRUE(crestHit.has_value());
    EXPECT_NEAR(1.0 - crestHit->distance, crest, 1e-9);
    // The declared bounds hold it and hug it: 0.294, 1.7 mm of margin above the crest.
    EXPECT_GE(bounds.max.y, crest);
    EXPECT_LE(bounds.max.y - crest, 0.002);
    // Down the axis, the first surface is the top of the orb (centre y 0.205, radius 0.042).
    const auto top = sculpture->intersect({{0.0, 1.0, 0.0}, {0.0, -1.0, 0.0}}, 10.0);
    ASSERT_TRUE(top.has_value());
    EXPECT_NEAR(1.0 - top->distance, 0.247, 1e-9);  // the bowl's fillet is far from the axis
    // The thin ring (tube radius 2.8 mm) is hit where it crosses the X axis, beside the knob.
    const auto ring = sculpture->intersect({{0.095, 1.0, 0.0}, {0.0, -1.0, 0.0}}, 10.0);
    ASSERT_TRUE(ring.has_value());
    EXPECT_GT(1.0 - ring->distance, 0.235);
    EXPECT_LT(1.0 - ring->distance, 0.235 + 0.0081);  // within the knob (radius 7.5 mm) or ring
    // The plinth's side is carved by a groove 5 mm deep at mid height.
    const auto groove = sculpture->intersect({{1.0, 0.0175, 0.0}, {-1.0, 0.0, 0.0}}, 10.0);
    ASSERT_TRUE(groove.has_value());
    // The lip's rounding (2 mm) does not reach the groove's bottom, so this is exact.
    EXPECT_NEAR(1.0 - groove->distance, 0.075, 1e-9);
}

TEST(MarbleTest, IsDeterministicWhiteWithDarkerVeins) {
    const MarbleAlbedo marble(0.1);
    const MarbleAlbedo same(0.1);
    std::mt19937_64 random(5);
    std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
    int light = 0, vein = 0;
    for (int i = 0; i < 20000; ++i) {
        const glm::dvec3 p(coordinate(random), coordinate(random), coordinate(random));
        const glm::vec3 albedo = marble(p);
        ASSERT_EQ(albedo, same(p));
        for (int c = 0; c < 3; ++c) {
            ASSERT_GE(albedo[c], 0.0f);
            ASSERT_LE(albedo[c], 1.0f);
        }
        const float mean = (albedo.r + albedo.g + albedo.b) / 3.0f;
        light += mean > 0.7f ? 1 : 0;
        vein += mean < 0.5f ? 1 : 0;
        if (mean < 0.5f) {
            EXPECT_GT(albedo.g, albedo.r);  // veins are grey-green
        }
    }
    EXPECT_GT(light, 20000 * 7 / 10);  // mostly white stone
    EXPECT_GT(vein, 20000 / 200);      // but veins are there
}

TEST(MarbleTest, GradientNoiseIsZeroOnTheLatticeAndBounded) {
    EXPECT_EQ(gradientNoise({3.0, -2.0, 7.0}), 0.0);
    std::mt19937_64 random(6);
    std::uniform_real_distribution<double> coordinate(-50.0, 50.0);
    for (int i = 0; i < 10000; ++i) {
        // Improved Perlin noise in 3-D stays within about +-1.04.
        EXPECT_LE(
            std::abs(gradientNoise({coordinate(random), coordinate(random), coordinate(random)})),
            1.1);
    }
}

}  // namespace
}  // namespace subscan
