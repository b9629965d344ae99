#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/Srgb.h"
#include "scan/Scene.h"
#include "scan/VirtualScanner.h"
#include "support/TestMeshes.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using Color = ScannerSettings::Color;
using ::testing::HasSubstr;

double sceneSize(const Scene& scene) {
    return glm::length(scene.bounds().extent());
}

/// Small scans keep the suite fast: 8 views of 48 x 48 rays still give thousands of points.
ScannerSettings smallScan() {
    ScannerSettings settings;
    settings.resolution = 48;
    settings.normals = true;
    return settings;
}

/// Positions are stored as floats relative to the centre of the bounds: each coordinate is
/// rounded by at most half a float step at the cloud's half size, so a point can sit this far
/// off the exact surface even without noise.
double floatStorageError(const PointCloud& cloud) {
    const glm::dvec3 half = 0.5 * cloud.bounds.extent();
    return std::sqrt(3.0) * 0.5 * std::numeric_limits<float>::epsilon() *
           std::max({half.x, half.y, half.z});
}

class ScannedSceneTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ScannedSceneTest, WithoutNoiseEveryPointIsOnTheSurface) {
    const auto scene = makeBuiltInScene(GetParam());
    const PointCloud cloud = scanScene(*scene, smallScan());
    ASSERT_GT(cloud.size(), 1000u);
    // Hits are refined to 1e-11 of the size; what is left is float storage.
    const double tolerance = 1e-9 * sceneSize(*scene) + floatStorageError(cloud);
    EXPECT_LE(tolerance, 1e-7 * sceneSize(*scene));
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        ASSERT_LE(scene->surfaceDistance(cloud.fileCoordinates(i)), tolerance) << "point " << i;
    }
}

/// A ray of the scan and the surface it hit, cast here again as scanScene documents it: every
/// view of scannerViews, a resolution x resolution grid of rays through pixel centres, the first
/// hit within the scanner's reach of 4 bounding-sphere radii, in the order of the cloud's points.
struct ScanRay {
    glm::dvec3 origin;
    glm::dvec3 direction;  // unit
    glm::dvec3 normal;     // the surface's at the noiseless hit
    double distance;       // to the noiseless hit
};

std::vector<ScanRay> scanRays(const Scene& scene, const ScannerSettings& settings) {
    const Bounds bounds = scene.bounds();
    const double reach = 4.0 * 0.5 * glm::length(bounds.extent());
    std::vector<ScanRay> rays;
    for (const ScannerView& view : scannerViews(bounds, settings.views)) {
        for (int row = 0; row < settings.resolution; ++row) {
            const double y = (1.0 - 2.0 * (row + 0.5) / settings.resolution) * view.tanHalfFov;
            for (int column = 0; column < settings.resolution; ++column) {
                const double x =
                    (2.0 * (column + 0.5) / settings.resolution - 1.0) * view.tanHalfFov;
                const Ray ray{view.position,
                              glm::normalize(view.forward + x * view.right + y * view.up)};
                if (const auto hit = scene.intersect(ray, reach)) {
                    rays.push_back({ray.origin, ray.direction, hit->normal, hit->distance});
                }
            }
        }
    }
    return rays;
}

TEST_P(ScannedSceneTest, NoiseMovesPointsOffTheSurfaceByAboutSigma) {
    const auto scene = makeBuiltInScene(GetParam());
    ScannerSettings settings = smallScan();
    settings.noise = 0.5;
    settings.noiseInSpacingUnits = true;
    const double sigma = noiseSigma(scene->bounds(), settings);
    EXPECT_DOUBLE_EQ(sigma, 0.5 * scanSpacing(scene->bounds(), settings));
    const PointCloud cloud = scanScene(*scene, settings);
    const std::vector<ScanRay> rays = scanRays(*scene, settings);
    ASSERT_EQ(rays.size(), cloud.size());
    double sumOfSquares = 0.0, sumCos2 = 0.0, sumCos4 = 0.0;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec3 p = cloud.fileCoordinates(i);
        const ScanRay& ray = rays[i];
        // Point i was moved along ray i only: it lies on the ray, up to float storage (plus
        // 1e-12 for the double arithmetic, ~1e-15 at these distances).
        const glm::dvec3 fromOrigin = p - ray.origin;
        ASSERT_LE(glm::length(fromOrigin - glm::dot(fromOrigin, ray.direction) * ray.direction),
                  floatStorageError(cloud) + 1e-12)
            << "point " << i;
        const double distance = scene->surfaceDistance(p);
        // A point is at most its range error from the surface. 6 sigma, not 5: among ~10^4
        // points a 5-sigma draw (p = 6e-7 each) may well happen, a 6-sigma one (2e-9) not.
        ASSERT_LE(distance, 6.0 * sigma + floatStorageError(cloud)) << "point " << i;
        sumOfSquares += distance * distance;
        const double cosine = std::abs(glm::dot(ray.normal, ray.direction));
        sumCos2 += cosine * cosine;
        sumCos4 += cosine * cosine * cosine * cosine;
    }
    const double n = static_cast<double>(cloud.size());
    const double rms = std::sqrt(sumOfSquares / n);
    // Range noise g sigma along a ray (g standard normal) moves its point off the tangent plane
    // at the hit by |g| sigma cos(theta), theta between the ray and the normal. Over these rays
    // the expected rms is sigma sqrt(mean cos^2): 0.70 sigma on the sphere, 0.68-0.70 on the
    // others.
    const double expected = sigma * std::sqrt(sumCos2 / n);
    // Statistical margin: rms^2 is the mean of n draws of sigma^2 cos^2 g^2 (Var g^2 = 2), so
    // its relative standard deviation is sqrt(2 sum cos^4) / sum cos^2, and the rms's half of
    // that: 1.0-1.4 % for these 3,600-7,300 points. Four of them (p = 6e-5 per side) hold any
    // fair draw of the noise. Curvature adds a second-order 3/4 sigma^2 kappa^2 sin^4 to the
    // squares, under 1 % of the rms even on the torus's 35 mm tube.
    const double margin = 4.0 * 0.5 * std::sqrt(2.0 * sumCos4) / sumCos2;
    // On the sculpture surfaceDistance is only a lower bound (smooth unions), and the fins
    // (4 mm) and the ring's tube (5.6 mm) are thinner than +-sigma (4.4 mm): a point pushed
    // through one lies near its far side. Measured 2026-12-03, rms / expected: sphere 0.9987,
    // torus 0.9884, box-with-hole 0.9757 (its concave edges, 2.4 sd), sculpture 0.8812; the
    // sculpture's shortfall of 12 % is allowed below, nothing more.
    const double shortfall = GetParam() == "sculpture" ? 0.12 : 0.0;
    EXPECT_LE(rms, expected * (1.0 + margin));
    EXPECT_GE(rms, expected * (1.0 - shortfall - margin));
}

TEST_P(ScannedSceneTest, NormalsAreUnitAndFaceTheScanner) {
    const auto scene = makeBuiltInScene(GetParam());
    ScannerSettings settings = smallScan();
    settings.views = 1;
    const PointCloud cloud = scanScene(*scene, settings);
    ASSERT_TRUE(cloud.hasNormals());
    const glm::dvec3 scanner = scannerViews(scene->bounds(), 1).front().position;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const glm::dvec3 normal(cloud.normals[i]);
        EXPECT_NEAR(glm::length(normal), 1.0, 1e-6);  // unit in double, rounded to float
        // Facing: the ray entered through this side. Float rounding of the normal allows a
        // grazing one to dip by ~1e-7.
        EXPECT_GT(glm::dot(normal, glm::normalize(scanner - cloud.fileCoordinates(i))), -1e-6)
            << "point " << i;
    }
}

TEST_P(ScannedSceneTest, PointCountGrowsWithTheSquareOfTheResolution) {
    const auto scene = makeBuiltInScene(GetParam());
    ScannerSettings settings;
    settings.color = Color::None;
    settings.resolution = 64;
    const double coarse = static_cast<double>(scanScene(*scene, settings).size());
    settings.resolution = 128;
    const double fine = static_cast<double>(scanScene(*scene, settings).size());
    // Each pixel is a sample of the covered area; only pixels on a silhouette (a few percent of
    // the covered ones at 64 x 64) change the ratio, so 4 within 6 %.
    EXPECT_NEAR(fine / coarse, 4.0, 0.25);
}

INSTANTIATE_TEST_SUITE_P(AllScenes, ScannedSceneTest,
                         ::testing::Values("sphere", "torus", "box-with-hole", "sculpture"),
                         [](const auto& testParam) {
                             std::string name = testParam.param;
                             std::erase(name, '-');
                             return name;
                         });

/// A unit sphere with a second sphere of radius 0.5 inside it: the inner one can never be seen.
class NestedSpheres final : public Scene {
  public:
    std::optional<SurfaceHit> intersect(const Ray& ray, double maxDistance) const override {
        std::optional<SurfaceHit> nearest;
        for (const double radius : {1.0, 0.5}) {
            const double b = glm::dot(ray.origin, ray.direction);
            const double c = glm::dot(ray.origin, ray.origin) - radius * radius;
            const double discriminant = b * b - c;
            if (discriminant < 0.0) {
                continue;
            }
            for (const double t : {-b - std::sqrt(discriminant), -b + std::sqrt(discriminant)}) {
                if (t >= 0.0 && t < maxDistance && (!nearest || t < nearest->distance)) {
                    const glm::dvec3 normal = (ray.origin + t * ray.direction) / radius;
                    nearest = SurfaceHit{t, facingRay(normal, ray.direction), glm::vec3(0.5f)};
                }
            }
        }
        return nearest;
    }
    Bounds bounds() const override {
        Bounds bounds;
        bounds.add(glm::dvec3(-1.0));
        bounds.add(glm::dvec3(1.0));
        return bounds;
    }
    double surfaceDistance(const glm::dvec3& p) const override {
        return std::min(std::abs(glm::length(p) - 1.0), std::abs(glm::length(p) - 0.5));
    }
};

TEST(VirtualScannerTest, HiddenSurfacesAreNeverScanned) {
    const PointCloud cloud = scanScene(NestedSpheres(), smallScan());
    ASSERT_GT(cloud.size(), 1000u);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        ASSERT_GT(glm::length(cloud.fileCoordinates(i)), 0.99) << "point " << i;
    }
}

TEST(VirtualScannerTest, HiddenTrianglesAreNeverScanned) {
    // The same as meshes: only the BVH's ordering of hits keeps the inner shell hidden.
    const auto scene = makeMeshScene(test::sphereMeshes({1.0, 0.5}, 16, 32));
    const PointCloud cloud = scanScene(*scene, smallScan());
    ASSERT_GT(cloud.size(), 1000u);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        // The outer shell's chords sag by 1 - cos(pi / 32) = 0.5 % at most.
        ASSERT_GT(glm::length(cloud.fileCoordinates(i)), 0.99) << "point " << i;
    }
}

TEST(VirtualScannerTest, TheSameSeedGivesTheSameCloudWhateverTheThreads) {
    const auto scene = makeBuiltInScene("sculpture");
    ScannerSettings settings = smallScan();
    settings.noise = 0.3;
    settings.noiseInSpacingUnits = true;
    settings.seed = 42;
    const PointCloud one = scanScene(*scene, settings, 1);
    const PointCloud three = scanScene(*scene, settings, 3);
    ASSERT_EQ(one.size(), three.size());
    EXPECT_EQ(one.origin, three.origin);
    EXPECT_EQ(one.positions, three.positions);
    EXPECT_EQ(one.colors, three.colors);
    EXPECT_EQ(one.normals, three.normals);

    settings.seed = 43;
    const PointCloud other = scanScene(*scene, settings, 1);
    ASSERT_EQ(other.size(), one.size());  // noise moves points, it never adds or drops them
    EXPECT_NE(other.positions, one.positions);
}

TEST(VirtualScannerTest, ColoursFollowTheSetting) {
    const auto sphere = makeBuiltInScene("sphere");
    ScannerSettings settings = smallScan();
    settings.normals = false;
    settings.color = Color::None;
    const PointCloud plain = scanScene(*sphere, settings);
    EXPECT_FALSE(plain.hasColors());
    EXPECT_FALSE(plain.hasNormals());

    settings.color = Color::Scene;
    const PointCloud sceneColours = scanScene(*sphere, settings);
    const Rgba8 expected = srgb8Color(sphere->intersect({{0, 0, 5}, {0, 0, -1}}, 10.0)->albedo);
    for (const Rgba8& color : sceneColours.colors) {
        ASSERT_EQ(color, expected);  // the sphere is one plain colour
    }

    settings.color = Color::Marble;
    const PointCloud marble = scanScene(*sphere, settings);
    int darker = 0;
    for (const Rgba8& color : marble.colors) {
        darker += color.r < 150 ? 1 : 0;
    }
    EXPECT_GT(darker, 0);                                    // veins
    EXPECT_LT(darker, static_cast<int>(marble.size()) / 2);  // on white stone
}

TEST(VirtualScannerTest, ViewsRingTheSceneWithATopViewFromFive) {
    Bounds bounds;
    bounds.add({-1.0, 0.0, -1.0});
    bounds.add({1.0, 2.0, 1.0});
    const glm::dvec3 centre(0.0, 1.0, 0.0);
    const double radius = std::sqrt(3.0);
    const auto views = scannerViews(bounds, 8);
    ASSERT_EQ(views.size(), 8u);
    for (std::size_t k = 0; k < views.size(); ++k) {
        const ScannerView& view = views[k];
        // Exact geometry in double; 1e-12 is rounding.
        EXPECT_NEAR(glm::length(view.position - centre), 3.0 * radius, 1e-12);
        EXPECT_NEAR(glm::dot(view.forward, glm::normalize(centre - view.position)), 1.0, 1e-12);
        EXPECT_NEAR(glm::dot(view.right, view.up), 0.0, 1e-12);
        EXPECT_NEAR(glm::dot(view.right, view.forward), 0.0, 1e-12);
        // The image's half side subtends the bounding sphere exactly.
        EXPECT_NEAR(std::atan(view.tanHalfFov), std::asin(1.0 / 3.0), 1e-12);
        const double elevation = std::asin((view.position.y - centre.y) / (3.0 * radius));
        const double expected = k == 7 ? 90.0 : (k % 2 == 0 ? 25.0 : -25.0);
        EXPECT_NEAR(glm::degrees(elevation), expected, 1e-9) << "view " << k;
    }
    const auto four = scannerViews(bounds, 4);
    ASSERT_EQ(four.size(), 4u);
    EXPECT_NEAR(four[1].position.x, centre.x + 3.0 * radius * std::cos(glm::radians(25.0)),
                1e-12);  // a quarter turn round the ring, below the centre
}

TEST(VirtualScannerTest, ScanToPointCountGivesExactlyThatManyPoints) {
    const auto scene = makeBuiltInScene("box-with-hole");
    ScannerSettings settings = smallScan();
    for (const std::size_t count : {1u, 7u, 500u, 20000u}) {
        EXPECT_EQ(scanToPointCount(*scene, settings, count).size(), count);
    }
    EXPECT_THROW(scanToPointCount(*scene, settings, 0), Error);
}

TEST(VirtualScannerTest, ScanToPointCountKeepsPointsFromAllOverTheScene) {
    const auto scene = makeBuiltInScene("sculpture");
    const PointCloud cloud = scanToPointCount(*scene, smallScan(), 2000);
    const glm::dvec3 covered = cloud.bounds.extent() / scene->bounds().extent();
    // Kept points are spread through every view and row, so they reach nearly to the scene's
    // bounds on every axis (2000 points are ~4 mm apart on a 30 cm object: 3 % of its size).
    for (int axis = 0; axis < 3; ++axis) {
        EXPECT_GT(covered[axis], 0.95) << "axis " << axis;
    }
}

TEST(VirtualScannerTest, SettingsRoundTripThroughJson) {
    ScannerSettings settings;
    settings.views = 12;
    settings.resolution = 300;
    settings.noise = 0.25;
    settings.noiseInSpacingUnits = true;
    settings.color = Color::Marble;
    settings.normals = true;
    settings.seed = 0xFFFFFFFFFFFFFFFFull;
    const nlohmann::json json = settings;
    EXPECT_EQ(json["color"], "marble");
    EXPECT_EQ(json.get<ScannerSettings>(), settings);
    EXPECT_EQ(nlohmann::json::object().get<ScannerSettings>(), ScannerSettings());

    auto error = [](const nlohmann::json& bad) {
        return test::errorMessage([&] { bad.get<ScannerSettings>(); });
    };
    EXPECT_THAT(error({{"views", 0}}), HasSubstr("1 to 1000 views"));
    EXPECT_THAT(error({{"resolution", "big"}}), HasSubstr("'resolution' has the wrong type"));
    EXPECT_THAT(error({{"noise", -1.0}}), HasSubstr("noise must be"));
    EXPECT_THAT(error({{"color", "purple"}}), HasSubstr("'purple', not none, scene or marble"));
    EXPECT_THAT(error({{"colour", "scene"}}), HasSubstr("'colour' is not a scanner setting"));
    EXPECT_THAT(error(nlohmann::json::array()), HasSubstr("must be a JSON object"));
}

TEST(VirtualScannerTest, NoiseAmountsParseInMetresOrSpacings) {
    EXPECT_EQ(parseNoiseAmount("0.0002")->value, 0.0002);
    EXPECT_FALSE(parseNoiseAmount("0.0002")->inSpacingUnits);
    EXPECT_EQ(parseNoiseAmount("0.1h")->value, 0.1);
    EXPECT_TRUE(parseNoiseAmount("0.1h")->inSpacingUnits);
    EXPECT_EQ(parseNoiseAmount("0")->value, 0.0);
    for (const char* bad : {"", "h", "-1", "1e400", "nan", "1 h", "1hh", "0.1m", "inf"}) {
        EXPECT_FALSE(parseNoiseAmount(bad).has_value()) << bad;
    }
}

TEST(VirtualScannerTest, SpacingIsThePixelFootprintAtTheCentre) {
    Bounds bounds;
    bounds.add(glm::dvec3(-1.0));
    bounds.add(glm::dvec3(1.0));
    ScannerSettings settings;
    settings.resolution = 100;
    // Distance 3 r, half field tan = 1 / sqrt(8): the image spans 2 * 3 r / sqrt(8) at the
    // centre, r = sqrt(3).
    EXPECT_NEAR(scanSpacing(bounds, settings), 6.0 * std::sqrt(3.0) / std::sqrt(8.0) / 100.0,
                1e-15);
    settings.noise = 0.002;
    EXPECT_EQ(noiseSigma(bounds, settings), 0.002);
}

TEST(VirtualScannerTest, BadSettingsAreRefused) {
    const auto sphere = makeBuiltInScene("sphere");
    ScannerSettings settings;
    settings.views = 0;
    EXPECT_THROW(scanScene(*sphere, settings), Error);
    settings = ScannerSettings();
    settings.resolution = kMaxScannerResolution + 1;
    EXPECT_THROW(scanScene(*sphere, settings), Error);
    settings = ScannerSettings();
    settings.noise = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(scanScene(*sphere, settings), Error);
}

}  // namespace
}  // namespace subscan
