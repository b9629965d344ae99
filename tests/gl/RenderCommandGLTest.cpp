// `subscan render` end to end: the exported buffers can be reproduced from the scan and
// camera.json alone, far-from-origin clouds render without quantisation, and bad requests fail
// with one sentence and no output file.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/matrix.hpp>
#include <nlohmann/json.hpp>

#include "core/Srgb.h"
#include "eval/GroundTruth.h"
#include "io/CameraJson.h"
#include "io/Image.h"
#include "render/SurfaceSettings.h"
#include "scan/Scene.h"
#include "support/GlTestSupport.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using test::runSubscan;
using ::testing::HasSubstr;

constexpr int kWidth = 61;
constexpr int kHeight = 47;

/// A camera for the test, written as camera.json by hand (row-major rows).
nlohmann::json cameraJson(const glm::dmat4& view) {
    nlohmann::json rows = nlohmann::json::array();
    for (int r = 0; r < 4; ++r) {
        rows.push_back({view[0][r], view[1][r], view[2][r], view[3][r]});
    }
    return {{"width", kWidth}, {"height", kHeight}, {"fovy_deg", 40.0},
            {"near", 0.5},     {"far", 30.0},       {"view", rows}};
}

glm::dmat4 rowsToMatrix(const nlohmann::json& rows) {
    glm::dmat4 m(0.0);
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) {
            m[c][r] = rows.at(r).at(c).get<double>();
        }
    }
    return m;
}

/// Points in front of the camera `view` that land inside pixels (0.2..0.8 of the way across),
/// all at distinct depths.
std::vector<glm::dvec3> makePoints(const glm::dmat4& view) {
    std::mt19937 random(11);
    std::uniform_real_distribution<double> within(0.2, 0.8);
    const double tanHalf = std::tan(glm::radians(20.0));
    const double aspect = static_cast<double>(kWidth) / kHeight;
    const glm::dmat4 toWorld = glm::inverse(view);
    std::vector<glm::dvec3> points;
    for (int i = 0; i < 2500; ++i) {
        const double x = (random() % kWidth) + within(random);
        const double y = (random() % kHeight) + within(random);
        const double depth = 4.0 + 0.002 * i;
        const double ndcX = 2.0 * x / kWidth - 1.0;
        const double ndcY = 1.0 - 2.0 * y / kHeight;
        const glm::dvec4 v(ndcX * depth * tanHalf * aspect, ndcY * depth * tanHalf, -depth, 1);
        points.push_back(glm::dvec3(toWorld * v));
    }
    return points;
}

/// An ascii PLY with 17 significant digits, so the file holds the doubles exactly.
std::string asciiPly(const std::vector<glm::dvec3>& points) {
    std::ostringstream ply;
    ply.precision(17);
    ply << "ply\nformat ascii 1.0\nelement vertex " << points.size()
        << "\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
    for (const glm::dvec3& p : points) {
        ply << p.x << ' ' << p.y << ' ' << p.z << '\n';
    }
    return ply.str();
}

/// A PFM reader written here, independent of subscan's, as an outside tool would.
std::vector<float> readDepthPfm(const std::filesystem::path& path, int& width, int& height) {
    std::ifstream stream(path, std::ios::binary);
    std::string magic;
    double scale = 0;
    stream >> magic >> width >> height >> scale;
    stream.get();
    EXPECT_EQ(magic, "Pf");
    EXPECT_LT(scale, 0.0);  // little-endian
    std::vector<float> bottomUp(static_cast<std::size_t>(width * height));
    stream.read(reinterpret_cast<char*>(bottomUp.data()),
                static_cast<std::streamsize>(bottomUp.size() * sizeof(float)));
    std::vector<float> topDown(bottomUp.size());
    for (int y = 0; y < height; ++y) {
        std::memcpy(&topDown[static_cast<std::size_t>(y * width)],
                    &bottomUp[static_cast<std::size_t>((height - 1 - y) * width)],
                    static_cast<std::size_t>(width) * sizeof(float));
    }
    return topDown;
}

TEST(RenderCommandGLTest, DepthPfmIsReproducibleFromTheScanAndCameraJson) {
    const test::TempDir dir;
    // UTM-sized coordinates: the check also covers the double-precision path.
    const glm::dvec3 offset(500000.0, 5400000.0, 120.0);
    const glm::dmat4 view = glm::lookAt(offset + glm::dvec3(1, 2, 8), offset, glm::dvec3(0, 1, 0));
    const std::vector<glm::dvec3> points = makePoints(view);
    const auto scan = dir.write("scan.ply", asciiPly(points));
    const auto camera = dir.write("camera.json", cameraJson(view).dump());
    const auto exported = dir / "buffers";

    const auto result =
        runSubscan({"render", scan.string(), "-o", (dir / "out.png").string(), "--camera",
                    camera.string(), "--export-buffers", exported.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;

    // From here on only the scan, camera.json and the pixel convention of docs/cli.md are used.
    std::ifstream cameraStream(exported / "camera.json");
    const nlohmann::json exportedCamera = nlohmann::json::parse(cameraStream);
    EXPECT_EQ(exportedCamera["width"], kWidth);
    EXPECT_EQ(exportedCamera["height"], kHeight);
    const glm::dmat4 exportedView = rowsToMatrix(exportedCamera["view"]);
    const glm::dmat4 projection = rowsToMatrix(exportedCamera["projection"]);
    const double nearPlane = exportedCamera["near"];
    const double farPlane = exportedCamera["far"];

    std::vector<double> expected(kWidth * kHeight, std::numeric_limits<double>::infinity());
    for (const glm::dvec3& p : points) {
        const glm::dvec4 v = exportedView * glm::dvec4(p, 1.0);
        const glm::dvec4 clip = projection * v;
        const double depth = -v.z;
        // Pixel (x, y), y from the top, covers NDC x in [2x/W-1, 2(x+1)/W-1] and
        // NDC y in [1-2(y+1)/H, 1-2y/H].
        const int x = static_cast<int>(std::floor((clip.x / clip.w + 1.0) * 0.5 * kWidth));
        const int y = static_cast<int>(std::floor((1.0 - clip.y / clip.w) * 0.5 * kHeight));
        if (depth < nearPlane || depth > farPlane || x < 0 || y < 0 || x >= kWidth ||
            y >= kHeight) {
            continue;
        }
        double& nearest = expected[static_cast<std::size_t>(y * kWidth + x)];
        nearest = std::min(nearest, depth);
    }

    int width = 0, height = 0;
    const std::vector<float> depth = readDepthPfm(exported / "depth.pfm", width, height);
    ASSERT_EQ(width, kWidth);
    ASSERT_EQ(height, kHeight);
    int covered = 0;
    for (std::size_t i = 0; i < expected.size(); ++i) {
        if (std::isinf(expected[i])) {
            EXPECT_TRUE(std::isinf(depth[i])) << "pixel " << i;
        } else {
            ++covered;
            // Float positions relative to the cloud centre (~1e-7 of a 10 m extent) and a float
            // transform on the GPU: depths around 5 agree to ~1e-6.
            EXPECT_NEAR(depth[i], expected[i], 1e-5 * expected[i]) << "pixel " << i;
        }
    }
    EXPECT_GT(covered, kWidth * kHeight / 2);
    EXPECT_TRUE(std::filesystem::exists(exported / "color.png"));
}

TEST(RenderCommandGLTest, FarFromTheOriginRendersLikeAtTheOrigin) {
    const test::TempDir dir;
    const glm::dvec3 offset(651234.0, 4123456.0, 35.0);
    const glm::dmat4 view = glm::lookAt(glm::dvec3(0.5, 1, 7), glm::dvec3(0), glm::dvec3(0, 1, 0));
    std::vector<glm::dvec3> points = makePoints(view);
    const auto near = dir.write("near.ply", asciiPly(points));
    for (glm::dvec3& p : points) {
        p += offset;
    }
    const auto far = dir.write("far.ply", asciiPly(points));
    const auto nearCamera = dir.write("near.json", cameraJson(view).dump());
    const auto farCamera =
        dir.write("far.json", cameraJson(view * glm::translate(glm::dmat4(1.0), -offset)).dump());

    for (const auto& [scan, camera, out] : {std::tuple{near, nearCamera, dir / "near.png"},
                                            std::tuple{far, farCamera, dir / "far.png"}}) {
        const auto result =
            runSubscan({"render", scan.string(), "-o", out.string(), "--camera", camera.string()});
        ASSERT_EQ(result.exitCode, 0) << result.err;
    }
    // 4e6 m stored as float would move points by 0.25 m, i.e. many pixels: identical images
    // show the double-precision path keeps every point in its pixel.
    EXPECT_EQ(test::fileBytes(dir / "near.png"), test::fileBytes(dir / "far.png"));
}

/// A camera file looking at the built-in sphere, which then stays 7 pixels from the image's
/// border: nearer than the fill's reach, the surface would grow to the border, where fill
/// removal counts beyond the image as surface (so that close-ups fill to their edges).
std::filesystem::path sphereCameraFile(const test::TempDir& dir) {
    return dir.write("camera.json", cameraJson(glm::lookAt(glm::dvec3(0.5, 0.4, 4.0),
                                                           glm::dvec3(0.0), glm::dvec3(0, 1, 0)))
                                        .dump());
}

/// The pixels of a camera file's view whose ray meets the analytic sphere.
class SphereTruth {
  public:
    explicit SphereTruth(const std::filesystem::path& cameraFile)
        : truth_(renderGroundTruth(*makeBuiltInScene("sphere"), readCameraFile(cameraFile))) {
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                if (covered(x, y)) {
                    ++pixels_;
                    rim_ += onRim(x, y) ? 1 : 0;
                }
            }
        }
    }

    const GroundTruthImages& images() const { return truth_; }
    bool covered(int x, int y) const {
        return x >= 0 && y >= 0 && x < kWidth && y < kHeight &&
               !std::isinf(truth_.depth[static_cast<std::size_t>(y * kWidth + x)]);
    }
    /// A pixel with a 4-neighbour on the other side of the silhouette: its centre and the
    /// points near it may fall on either side.
    bool onRim(int x, int y) const {
        const bool inside = covered(x, y);
        return covered(x - 1, y) != inside || covered(x + 1, y) != inside ||
               covered(x, y - 1) != inside || covered(x, y + 1) != inside;
    }

    /// Expects the picture's drawn (non-black) pixels within `reach` pixels of the sphere and
    /// on at least `leastCoverage` of its pixels, less those on its rim when that is 1.
    void expectDrawnOnTheSphere(const Image8& image, double leastCoverage, int reach) const {
        ASSERT_EQ(image.width, kWidth);
        ASSERT_GT(pixels_, kWidth * kHeight / 5) << "the sphere should fill much of the view";
        int drawnOnTruth = 0, outside = 0;
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                const std::size_t i = 4 * static_cast<std::size_t>(y * kWidth + x);
                if (image.pixels[i] + image.pixels[i + 1] + image.pixels[i + 2] == 0) {
                    continue;
                }
                bool nearTruth = false;
                for (int dy = -reach; dy <= reach; ++dy) {
                    for (int dx = -reach; dx <= reach; ++dx) {
                        nearTruth = nearTruth || covered(x + dx, y + dy);
                    }
                }
                outside += nearTruth ? 0 : 1;
                drawnOnTruth += covered(x, y) ? 1 : 0;
            }
        }
        EXPECT_EQ(outside, 0) << "drawn pixels far from the sphere";
        EXPECT_GE(drawnOnTruth, leastCoverage * pixels_ - (leastCoverage == 1.0 ? rim_ : 0))
            << "of " << pixels_ << " sphere pixels (" << rim_ << " on its rim)";
    }

  private:
    GroundTruthImages truth_;
    int pixels_ = 0;
    int rim_ = 0;
};

TEST(RenderCommandGLTest, EveryModeDrawsTheObjectWhereTheTruthIs) {
    const test::TempDir dir;
    const auto cameraFile = sphereCameraFile(dir);
    const SphereTruth truth(cameraFile);
    struct Expectation {
        const char* mode;
        double leastCoverage;  // of the truth's pixels
        int reach;             // pixels beyond the silhouette a drawn pixel may lie
    };
    // 3000 points, half of them facing the camera, put about 1.5 points in each of the
    // sphere's pixels: 1-pixel points leave about e^-1.5 = 22 % (more at the rim) empty, so
    // they must cover half; 4-pixel splats and the reconstructions close those holes and
    // lose at most rim pixels. Splats reach 2 pixels (half their size) out.
    for (const Expectation& expected : {Expectation{"points", 0.5, 1},
                                        {"points-gl", 0.5, 1},
                                        {"splats", 0.9, 2},
                                        {"surface", 1.0, 1},
                                        {"sss", 1.0, 1}}) {
        SCOPED_TRACE(expected.mode);
        const auto out = dir / (std::string(expected.mode) + ".png");
        const auto result =
            runSubscan({"render", "synthetic:sphere?points=3000", "-o", out.string(), "--mode",
                        expected.mode, "--camera", cameraFile.string(), "--background", "#000000",
                        "--material", "skin-deon", "--unit", "cm"});
        ASSERT_EQ(result.exitCode, 0) << result.err;
        truth.expectDrawnOnTheSphere(readPng(out), expected.leastCoverage, expected.reach);
    }
}

TEST(RenderCommandGLTest, RasterResolutionAndTimingsOptionsDoWhatTheySay) {
    const test::TempDir dir;
    const auto cameraFile = sphereCameraFile(dir);
    const SphereTruth truth(cameraFile);
    const auto render = [&](const std::string& name, std::vector<std::string> options) {
        std::vector<std::string> arguments{"render",       "synthetic:sphere?points=3000",
                                           "-o",           (dir / name).string(),
                                           "--camera",     cameraFile.string(),
                                           "--background", "#000000",
                                           "--mode",       "surface"};
        arguments.insert(arguments.end(), options.begin(), options.end());
        return runSubscan(arguments);
    };
    ASSERT_EQ(render("auto.png", {}).exitCode, 0);

    // --raster: the two-pass path is what auto picks without 64-bit atomics, the same picture;
    // forcing int64 there is one sentence.
    if (!test::glTestContext().capabilities().int64Atomics) {
        ASSERT_EQ(render("two-pass.png", {"--raster", "two-pass"}).exitCode, 0);
        EXPECT_EQ(test::fileBytes(dir / "two-pass.png"), test::fileBytes(dir / "auto.png"));
        const auto int64 = render("int64.png", {"--raster", "int64"});
        EXPECT_EQ(int64.exitCode, 1);
        EXPECT_THAT(int64.err, HasSubstr("needs GL_NV_shader_atomic_int64"));
    }

    // --timings: one line per pass of the surface pipeline and their total; the same picture.
    const auto timed = render("timed.png", {"--timings"});
    ASSERT_EQ(timed.exitCode, 0) << timed.err;
    EXPECT_EQ(test::fileBytes(dir / "timed.png"), test::fileBytes(dir / "auto.png"));
    std::istringstream lines(timed.out);
    std::vector<std::string> passes;
    double sum = 0.0, total = -1.0;
    for (std::string pass, unit; lines >> pass;) {
        double milliseconds = 0.0;
        lines >> milliseconds >> unit;
        EXPECT_EQ(unit, "ms");
        EXPECT_GE(milliseconds, 0.0) << pass;
        if (pass == "total") {
            total = milliseconds;
        } else {
            passes.push_back(pass);
            sum += milliseconds;
        }
    }
    EXPECT_EQ(passes,
              (std::vector<std::string>{"RasterizePoints", "MinDepthPyramid", "HiddenPointRemoval",
                                        "PullPush", "FillRemoval", "Normals", "FinishSurface"}));
    EXPECT_NEAR(total, sum, 0.0005 * static_cast<double>(passes.size() + 1))  // 3 decimals each
        << timed.out;

    // --resolution half: the reconstruction runs at half the size (the buffers' camera, exported
    // beside the picture's, says so) and the picture, scaled up, still shows the sphere where it
    // is, within one reduced pixel (2 output pixels) of its silhouette.
    const auto half =
        render("half.png", {"--resolution", "half", "--export-buffers", (dir / "half").string()});
    ASSERT_EQ(half.exitCode, 0) << half.err;
    const Camera pipeline = readCameraFile(dir / "half" / "buffers_camera.json");
    EXPECT_EQ(pipeline.width, (kWidth + 1) / 2);
    EXPECT_EQ(pipeline.height, (kHeight + 1) / 2);
    EXPECT_EQ(readCameraFile(dir / "half" / "camera.json").width, kWidth);
    truth.expectDrawnOnTheSphere(readPng(dir / "half.png"), 1.0, 2);
    EXPECT_NE(test::fileBytes(dir / "half.png"), test::fileBytes(dir / "auto.png"));
}

TEST(RenderCommandGLTest, ExportedSurfaceBuffersMatchTheTruthAndTheShadingFormula) {
    // The surface mode's exported buffers of the built-in sphere: the mask and depth against
    // the analytic sphere, the normals against its normals, and the radiance against the
    // head light's Lambert plus Blinn-Phong on the exported normals and colour.
    const test::TempDir dir;
    const auto cameraFile = sphereCameraFile(dir);
    const auto exported = dir / "buffers";
    const auto result = runSubscan({"render", "synthetic:sphere?points=20000", "-o",
                                    (dir / "s.png").string(), "--mode", "surface", "--camera",
                                    cameraFile.string(), "--export-buffers", exported.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const Camera camera = readCameraFile(exported / "camera.json");
    const SphereTruth sphere(exported / "camera.json");
    const GroundTruthImages& truth = sphere.images();
    const ImageF depth = readPfm(exported / "depth.pfm");
    const ImageF normals = readPfm(exported / "normals.pfm");
    const ImageF radiance = readPfm(exported / "radiance.pfm");
    const Image8 mask = readPng(exported / "mask.png");
    const Image8 color = readPng(exported / "color.png");
    ASSERT_EQ(mask.channels, 1);
    const ShadingSettings shading;  // the defaults render used
    const double focal = camera.focalLengthPixels();
    int interior = 0, maskErrors = 0;
    std::vector<double> depthErrors;
    double normalErrorSum = 0.0;
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            const std::size_t i = static_cast<std::size_t>(y * kWidth + x);
            const bool shown = mask.pixels[i] == 255;
            EXPECT_EQ(shown, !std::isinf(depth.values[i])) << "mask and depth disagree";
            if (sphere.onRim(x, y)) {
                continue;
            }
            maskErrors += shown != sphere.covered(x, y) ? 1 : 0;
            if (!shown || !sphere.covered(x, y)) {
                continue;
            }
            ++interior;
            // In pixel footprints at that depth: a pixel shows its nearest point, which on a
            // tilted surface lies up to the slope times half a footprint in front of the centre.
            depthErrors.push_back(std::abs(double(depth.values[i]) - truth.depth[i]) /
                                  (truth.depth[i] / focal));
            const glm::dvec3 n(normals.values[3 * i], normals.values[3 * i + 1],
                               normals.values[3 * i + 2]);
            normalErrorSum += glm::degrees(std::acos(
                std::clamp(glm::dot(glm::normalize(n), glm::dvec3(truth.normals[i])), -1.0, 1.0)));
            // The radiance from the exported normal and colour.
            const glm::dvec3 position(depth.values[i] * (x + 0.5 - 0.5 * kWidth) / focal,
                                      depth.values[i] * (0.5 * kHeight - y - 0.5) / focal,
                                      -depth.values[i]);
            const double cosine = std::max(0.0, glm::dot(n, glm::normalize(-position)));
            for (int c = 0; c < 3; ++c) {
                const double albedo = srgbToLinear(color.pixels[4 * i + c] / 255.0f);
                const double expected =
                    albedo * (shading.ambient[c] + shading.headLight[c] * cosine) +
                    shading.headLight[c] * cosine * shading.specular *
                        std::pow(cosine, shading.shininess);
                // color.png holds the albedo in 8-bit sRGB: half a step is up to 0.5 % of a
                // mid-grey's linear value; the radiance itself is RGBA16F (~5e-4).
                EXPECT_NEAR(radiance.values[3 * i + c], expected, 0.01 * expected + 1e-3)
                    << x << "," << y << " channel " << c;
            }
        }
    }
    ASSERT_GT(interior, kWidth * kHeight / 4) << "the sphere should fill much of the view";
    EXPECT_EQ(maskErrors, 0) << "the mask differs from the sphere away from its rim";
    std::sort(depthErrors.begin(), depthErrors.end());
    // Measured 2026-12-03: median 0.25, 95th percentile 0.85 footprints (the largest, 1.5, at
    // the rim's grazing slopes); a surface off by half a pixel's footprint everywhere fails.
    EXPECT_LE(depthErrors[depthErrors.size() / 2], 0.4);
    EXPECT_LE(depthErrors[depthErrors.size() * 95 / 100], 1.2);
    // Measured 6.7 degrees; the evaluation's target for the mean normal error is 10.
    EXPECT_LE(normalErrorSum / interior, 10.0);
}

TEST(RenderCommandGLTest, ColorChoosesWhatThePointsShow) {
    const test::TempDir dir;
    const auto cameraFile = sphereCameraFile(dir);
    const auto render = [&](const std::string& color) {
        const auto out = dir / (color + ".png");
        const auto result =
            runSubscan({"render", "synthetic:sphere?points=3000", "-o", out.string(), "--camera",
                        cameraFile.string(), "--color", color, "--background", "#000000"});
        EXPECT_EQ(result.exitCode, 0) << color << ": " << result.err;
        return result.exitCode == 0 ? readPng(out) : Image8{};
    };
    // Uniform: every drawn point the same light grey (sRGB 200, through linear RGBA16F and
    // back: within one level).
    const Image8 uniform = render("uniform");
    int drawn = 0;
    for (std::size_t i = 0; i < uniform.pixels.size(); i += 4) {
        if (uniform.pixels[i] + uniform.pixels[i + 1] + uniform.pixels[i + 2] > 0) {
            ++drawn;
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(uniform.pixels[i + c], 200, 1);
            }
        }
    }
    EXPECT_GT(drawn, 300);
    // Height along y: the sphere's top rows are yellow-green, its bottom rows blue-violet
    // (viridis), so the top's green exceeds the bottom's by far.
    const Image8 height = render("height");
    const auto meanGreen = [&](int firstRow, int lastRow) {
        double sum = 0.0;
        int count = 0;
        for (int y = firstRow; y <= lastRow; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                const std::size_t i = 4 * static_cast<std::size_t>(y * kWidth + x);
                if (height.pixels[i] + height.pixels[i + 1] + height.pixels[i + 2] > 0) {
                    sum += height.pixels[i + 1];
                    ++count;
                }
            }
        }
        return count > 0 ? sum / count : 0.0;
    };
    EXPECT_GT(meanGreen(0, kHeight / 4), meanGreen(3 * kHeight / 4, kHeight - 1) + 80);
    // What the scan lacks is one sentence naming it.
    const auto noIntensity = runSubscan({"render", "synthetic:sphere?points=3000", "-o",
                                         (dir / "i.png").string(), "--color", "intensity"});
    EXPECT_EQ(noIntensity.exitCode, 1);
    EXPECT_THAT(noIntensity.err,
                HasSubstr("synthetic:sphere?points=3000: the scan has no intensities to show"));
}

TEST(RenderCommandGLTest, SavedSettingsHoldTheOptionsAndReproduceThePicture) {
    const test::TempDir dir;
    const auto cameraFile = sphereCameraFile(dir);
    const auto saved = dir / "saved.json";
    const std::vector<std::string> scene{"synthetic:sphere?points=3000", "--camera",
                                         cameraFile.string()};
    auto withScene = [&](std::vector<std::string> arguments) {
        arguments.insert(arguments.begin() + 1, scene.begin(), scene.end());
        return arguments;
    };
    const auto flagged =
        runSubscan(withScene({"render", "-o", (dir / "flags.png").string(), "--mode", "sss",
                              "--material", "skin-deon", "--unit", "cm", "--background", "#203040",
                              "--point-size", "3", "--save-settings", saved.string()}));
    ASSERT_EQ(flagged.exitCode, 0) << flagged.err;
    const nlohmann::json json = nlohmann::json::parse(test::fileBytes(saved));
    EXPECT_EQ(json["raster"]["mode"], "sss");
    EXPECT_EQ(json["raster"]["point_size"], 3.0);
    EXPECT_EQ(json["scattering"]["material"], "skin-deon");
    EXPECT_EQ(json["scattering"]["unit"], "cm");
    // #203040 as sRGB 0..1 (floats: within a float's step).
    EXPECT_NEAR(json["raster"]["background_srgb"][2].get<double>(), 0x40 / 255.0, 1e-6);
    const auto fromFile = runSubscan(
        withScene({"render", "-o", (dir / "file.png").string(), "--settings", saved.string()}));
    ASSERT_EQ(fromFile.exitCode, 0) << fromFile.err;
    EXPECT_EQ(test::fileBytes(dir / "file.png"), test::fileBytes(dir / "flags.png"));
    // And the file is what the options changed: without them the picture differs.
    const auto plain = runSubscan(withScene({"render", "-o", (dir / "plain.png").string()}));
    ASSERT_EQ(plain.exitCode, 0) << plain.err;
    EXPECT_NE(test::fileBytes(dir / "plain.png"), test::fileBytes(dir / "flags.png"));
}

TEST(RenderCommandGLTest, LinearPicturesAreTheExportedRadiance) {
    // -o .pfm and .exr write the radiance before the display transform: exactly the floats of
    // --export-buffers' radiance.pfm of the same render (one process each; the pipeline is
    // deterministic for one scan, camera and settings).
    const test::TempDir dir;
    const auto cameraFile = sphereCameraFile(dir);
    for (const char* mode : {"surface", "sss"}) {
        SCOPED_TRACE(mode);
        const std::vector<std::string> scene{"synthetic:sphere?points=20000", "--mode", mode,
                                             "--camera", cameraFile.string()};
        const auto render = [&](const std::filesystem::path& output, bool exportBuffers) {
            std::vector<std::string> arguments{"render", "-o", output.string()};
            arguments.insert(arguments.begin() + 1, scene.begin(), scene.end());
            if (exportBuffers) {
                arguments.push_back("--export-buffers");
                arguments.push_back((dir / mode).string());
            }
            const auto result = runSubscan(arguments);
            EXPECT_EQ(result.exitCode, 0) << result.err;
        };
        const auto pfm = dir / (std::string(mode) + ".pfm");
        const auto exr = dir / (std::string(mode) + ".EXR");
        render(pfm, true);
        render(exr, false);
        const ImageF radiance = readPfm(dir / mode / "radiance.pfm");
        ASSERT_EQ(radiance.width, kWidth);
        ASSERT_EQ(radiance.height, kHeight);
        const ImageF picture = readPfm(pfm);
        EXPECT_EQ(picture.channels, 3);
        EXPECT_EQ(picture.width, kWidth);
        EXPECT_EQ(picture.values, radiance.values);
        // Both PFM files store rows bottom to top: the same bytes, header included.
        EXPECT_EQ(test::fileBytes(pfm), test::fileBytes(dir / mode / "radiance.pfm"));
        const test::ExrFile file = test::readExr(exr);
        EXPECT_EQ(file.magic, 20000630u);
        EXPECT_EQ(file.image.width, kWidth);
        EXPECT_EQ(file.image.height, kHeight);
        EXPECT_EQ(file.image.values, radiance.values);
        // Not an empty frame that would match trivially: the lit sphere covers about half of it.
        const auto lit = std::count_if(radiance.values.begin(), radiance.values.end(),
                                       [](float value) { return value > 0.0f; });
        EXPECT_GT(lit, kWidth * kHeight / 4);
    }
}

TEST(RenderCommandGLTest, SensorViewLooksFromTheGivenSensorAtThePoints) {
    // A PLY has no sensor of its own: --sensor gives it, and camera.json shows the eye there,
    // looking at the middle of the points, Y up (PLY's default), at the asked size.
    const test::TempDir dir;
    const auto result = runSubscan({"render", "synthetic:sphere", "-o", (dir / "out.png").string(),
                                    "--view", "sensor", "--sensor", "0.5,0.2,3", "--width", "64",
                                    "--height", "48", "--export-buffers", (dir / "b").string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const Camera camera = readCameraFile(dir / "b" / "camera.json");
    // camera.json holds the view in doubles as printed by nlohmann (round-trip exact).
    EXPECT_LT(glm::length(camera.eye() - glm::dvec3(0.5, 0.2, 3.0)), 1e-12);
    EXPECT_EQ(camera.width, 64);
    const glm::dvec4 middle = camera.view * glm::dvec4(glm::dvec3(0.0), 1.0);
    // The sphere's framing box is centred on the origin up to its sampling: within 1 % of its
    // radius of the line of sight.
    EXPECT_LT(std::hypot(middle.x, middle.y), 0.01 * -middle.z);
    const Image8 picture = readPng(dir / "out.png");
    EXPECT_EQ(picture.width, 64);
}

TEST(RenderCommandGLTest, BadRequestsFailWithOneSentenceAndNoOutput) {
    const test::TempDir dir;
    const auto scan = dir.write("scan.ply", asciiPly({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
    const auto out = dir / "out.png";
    struct Case {
        std::vector<std::string> arguments;
        std::vector<std::string> environment;
        int exitCode;
        const char* message;
    };
    const auto badCamera = dir.write("bad.json", R"({"width": 10})");
    const std::vector<Case> cases{
        {{"render", scan.string(), "-o", scan.string()}, {}, 1, "over the input scan"},
        {{"render", scan.string(), "-o", (dir / "missing" / "x.png").string()},
         {},
         1,
         "does not exist"},
        {{"render", scan.string(), "-o", out.string(), "--camera", badCamera.string()},
         {},
         1,
         "the camera has no 'height'"},
        {{"render", scan.string(), "-o", out.string(), "--width", "60000"},
         {},
         1,
         "outside what the GPU can render"},
        {{"render", scan.string(), "-o", out.string(), "--view", "sensor"},
         {},
         1,
         "records no sensor position (a PCD VIEWPOINT, an E57 pose or an organised grid); give "
         "one with --sensor X,Y,Z"},
        {{"render", scan.string(), "-o", out.string(), "--view", "sensor", "--sensor", "1e9,0,0"},
         {},
         1,
         "the sensor position (1e+09, 0, 0) from --sensor is more than 20 times the points' "
         "extent away from them"},
        {{"render", scan.string(), "-o", out.string(), "--sensor", "1,2"},
         {},
         2,
         "'1,2' is not X,Y,Z"},
        {{"render", scan.string(), "-o", (dir / "out.bmp").string()},
         {},
         1,
         "pictures are written as .png or .jpg/.jpeg (sRGB) or as .pfm or .exr"},
        {{"render", scan.string(), "-o", (dir / "out.exr").string()},
         {},
         1,
         "out.exr: a .pfm or .exr picture is the linear radiance of the shaded surface; it "
         "needs --mode surface or sss"},
        {{"render", scan.string(), "-o", (dir / "out.exr").string(), "--mode", "surface", "--stage",
          "depth"},
         {},
         1,
         "a --stage view has none (write it as .png)"},
        {{"render", scan.string(), "-o", (dir / "out.exr").string(), "--mode", "sss", "--samples",
          "4"},
         {},
         1,
         "it is one frame's, so it needs --samples 1"},
        {{"render", scan.string(), "-o", (dir / "out.exr").string(), "--mode", "surface",
          "--resolution", "half"},
         {},
         1,
         "it needs --resolution full"},
        {{"render", scan.string(), "-o", out.string(), "--width", "0"}, {}, 2, ""},
        {{"render", scan.string(), "-o", out.string(), "--mode", "voxels"}, {}, 2, ""},
        {{"render", scan.string(), "-o", out.string(), "--mode", "sss", "--material", "jade"},
         {},
         2,
         "--material: there is no material 'jade'"},
        {{"render", scan.string(), "-o", out.string(), "--mode", "sss", "--scattering", "single",
          "--coefficients", "material", "--material", "marble-jimenez"},
         {},
         1,
         "the material 'marble-jimenez' is a Gaussian set without measured σs′ and σa"},
        {{"render", scan.string(), "-o", out.string(), "--mean-free-path", "1,2"},
         {},
         2,
         "--mean-free-path: '1,2' is not R,G,B"},
        {{"render", scan.string(), "-o", out.string(), "--mean-free-path", "1,0,2"},
         {},
         2,
         "--mean-free-path: 1,0,2 must be positive millimetres in every channel, not 0"},
        {{"render", scan.string(), "-o", out.string(), "--phase-g", "-1"},
         {},
         2,
         "--phase-g: -1 must lie strictly between -1 and 1"},
        {{"render", scan.string(), "-o", out.string(), "--eta", "0.8"},
         {},
         2,
         "--eta: 0.8 is outside 1..3"},
        {{"render", scan.string(), "-o", out.string(), "--single-samples", "65"},
         {},
         2,
         "--single-samples: 65 is outside 1..64"},
        {{"render", scan.string(), "-o", out.string(), "--scattering", "multiple"}, {}, 2, ""},
        // glvnd finds no EGL vendor: what a machine without any OpenGL driver looks like.
        {{"render", scan.string(), "-o", out.string()},
         {"__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/egl.json",
          "__EGL_VENDOR_LIBRARY_DIRS=/nonexistent"},
         1,
         "no usable OpenGL"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.arguments.back());
        const auto result = runSubscan(c.arguments, c.environment);
        EXPECT_EQ(result.exitCode, c.exitCode) << result.err;
        EXPECT_THAT(result.err, HasSubstr(c.message));
        if (c.exitCode == 1) {
            EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
        }
        EXPECT_FALSE(std::filesystem::exists(out));
        EXPECT_FALSE(std::filesystem::exists(dir / "out.exr"));
        EXPECT_FALSE(std::filesystem::exists(dir / "out.bmp"));
    }
    // The refused overwrite left the input intact.
    EXPECT_EQ(test::fileBytes(scan), asciiPly({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
}

TEST(RenderCommandGLTest, OutputsAreWrittenOnlyAfterTheWorkAndNeverOverAnInput) {
    const test::TempDir dir;
    const auto scan = dir.write("scan.ply", asciiPly({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));
    // --save-settings of a render that fails after the scan loads (the GPU cannot make a
    // picture that wide): no settings file, and the picture already there is kept.
    const auto settings = dir / "saved.json";
    const auto oldPicture = dir.write("wide.png", "an older picture");
    const auto tooWide = runSubscan({"render", scan.string(), "-o", oldPicture.string(), "--width",
                                     "60000", "--save-settings", settings.string()});
    EXPECT_EQ(tooWide.exitCode, 1) << tooWide.err;
    EXPECT_FALSE(std::filesystem::exists(settings));
    EXPECT_EQ(test::fileBytes(oldPicture), "an older picture");

    // --export-buffers into the folder whose camera.json is the --camera input.
    const std::string cameraText =
        cameraJson(
            glm::lookAt(glm::dvec3(0.3, 0.2, 4.0), glm::dvec3(0.3, 0.3, 0.0), glm::dvec3(0, 1, 0)))
            .dump();
    const auto camera = dir.write("camera.json", cameraText);
    const auto overCamera =
        runSubscan({"render", scan.string(), "-o", (dir / "x.png").string(), "--camera",
                    camera.string(), "--export-buffers", dir.path().string()});
    EXPECT_EQ(overCamera.exitCode, 1);
    EXPECT_THAT(overCamera.err, HasSubstr("refusing to write the camera over the input camera"));
    EXPECT_EQ(test::fileBytes(camera), cameraText);
    EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
    // Nor over (or removing) a buffers' camera given as --camera.
    std::filesystem::create_directory(dir / "own");
    const auto buffersCamera = dir.write("own/buffers_camera.json", cameraText);
    const auto overBuffersCamera =
        runSubscan({"render", scan.string(), "-o", (dir / "x.png").string(), "--camera",
                    buffersCamera.string(), "--export-buffers", (dir / "own").string()});
    EXPECT_EQ(overBuffersCamera.exitCode, 1);
    EXPECT_THAT(overBuffersCamera.err,
                HasSubstr("refusing to write the buffers' camera over the input camera"));
    EXPECT_EQ(test::fileBytes(buffersCamera), cameraText);

    // A picture or settings file into a folder that does not exist: said before any output is
    // written (the buffers were written, then the picture failed).
    for (const auto& [picture, saved] : {std::pair{dir / "missing" / "x.png", dir / "s.json"},
                                         std::pair{dir / "x.png", dir / "missing" / "s.json"}}) {
        const auto missing =
            runSubscan({"render", scan.string(), "-o", picture.string(), "--export-buffers",
                        (dir / "early").string(), "--save-settings", saved.string()});
        EXPECT_EQ(missing.exitCode, 1);
        EXPECT_THAT(missing.err, HasSubstr("missing does not exist"));
        EXPECT_FALSE(std::filesystem::exists(dir / "early"));
        EXPECT_FALSE(std::filesystem::exists(dir / "x.png"));
    }

    // A .jpg output is a JPEG.
    const auto jpeg = runSubscan({"render", scan.string(), "-o", (dir / "view.jpg").string()});
    ASSERT_EQ(jpeg.exitCode, 0) << jpeg.err;
    EXPECT_EQ(test::fileBytes(dir / "view.jpg").substr(0, 3), "\xFF\xD8\xFF");

    // The same render to another folder succeeds and writes every output.
    const auto good = runSubscan(
        {"render", scan.string(), "-o", (dir / "x.png").string(), "--camera", camera.string(),
         "--export-buffers", (dir / "buffers").string(), "--save-settings", settings.string()});
    ASSERT_EQ(good.exitCode, 0) << good.err;
    EXPECT_TRUE(std::filesystem::exists(dir / "x.png"));
    EXPECT_TRUE(std::filesystem::exists(dir / "buffers" / "camera.json"));
    EXPECT_TRUE(std::filesystem::exists(settings));
}

TEST(RenderCommandGLTest, AnExportedCameraRendersItsPictureAgain) {
    // With --samples the buffers come from the last, jittered frame; camera.json is the
    // picture's camera all the same, so --camera renders the same picture (it used to carry
    // that frame's jitter, which --camera then added to every frame's own: found from outside).
    const test::TempDir dir;
    auto render = [&](const std::string& name, std::vector<std::string> extra) {
        std::vector<std::string> arguments{"render",
                                           "synthetic:sphere?points=20000",
                                           "-o",
                                           (dir / (name + ".png")).string(),
                                           "--export-buffers",
                                           (dir / name).string(),
                                           "--mode",
                                           "surface",
                                           "--samples",
                                           "4"};
        arguments.insert(arguments.end(), extra.begin(), extra.end());
        return runSubscan(arguments);
    };
    const auto first = render("first", {"--width", "48", "--height", "40", "--yaw", "20"});
    ASSERT_EQ(first.exitCode, 0) << first.err;
    const auto again = render("again", {"--camera", (dir / "first" / "camera.json").string()});
    ASSERT_EQ(again.exitCode, 0) << again.err;
    EXPECT_EQ(test::fileBytes(dir / "again.png"), test::fileBytes(dir / "first.png"));
    EXPECT_EQ(test::fileBytes(dir / "again" / "camera.json"),
              test::fileBytes(dir / "first" / "camera.json"));
    EXPECT_EQ(readCameraFile(dir / "first" / "camera.json").jitterPixels, glm::dvec2(0.0));
    // The buffers' own camera, jittered, beside it: what their pixels were rendered through.
    const Camera buffers = readCameraFile(dir / "first" / "buffers_camera.json");
    EXPECT_NE(buffers.jitterPixels, glm::dvec2(0.0));
    EXPECT_EQ(buffers.width, 48);

    // Without jitter or reduction the two are one: no buffers_camera.json, not even an earlier
    // export's left in the folder.
    const auto plain = runSubscan({"render", "synthetic:sphere?points=20000", "-o",
                                   (dir / "plain.png").string(), "--export-buffers",
                                   (dir / "first").string(), "--width", "48", "--height", "40"});
    ASSERT_EQ(plain.exitCode, 0) << plain.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "first" / "buffers_camera.json"));
}

TEST(RenderCommandGLTest, AReusedExportFolderHoldsThisExportAlone) {
    // An export into the folder of an earlier one of another mode kept that one's buffers
    // (single.pfm, normals.pfm, ...), which passed for this picture's.
    const test::TempDir dir;
    const auto exported = dir / "buffers";
    auto render = [&](std::vector<std::string> options) {
        std::vector<std::string> arguments{"render",           "synthetic:sphere?points=4000",
                                           "--width",          "32",
                                           "--height",         "24",
                                           "--export-buffers", exported.string()};
        arguments.insert(arguments.end(), options.begin(), options.end());
        return runSubscan(arguments);
    };
    const auto single =
        render({"-o", (dir / "single.png").string(), "--mode", "sss", "--scattering", "single"});
    ASSERT_EQ(single.exitCode, 0) << single.err;
    EXPECT_TRUE(std::filesystem::exists(exported / "sigma_a.pfm"));
    // The picture and the settings may lie in the folder, and stay there when it is reused.
    const auto picture = exported / "points.png";
    const auto settings = exported / "settings.json";
    for (int run = 0; run < 2; ++run) {
        const auto points = render(
            {"-o", picture.string(), "--mode", "points", "--save-settings", settings.string()});
        ASSERT_EQ(points.exitCode, 0) << points.err;
        EXPECT_EQ(test::folderEntries(exported),
                  (std::vector<std::string>{"camera.json", "color.png", "depth.pfm", "points.png",
                                            "settings.json"}));
    }

    // Anything else there might be someone's: refused before anything is written.
    const auto notes = dir.write("buffers/notes.txt", "mine");
    std::filesystem::remove(picture);
    std::filesystem::remove(settings);
    const auto refused = render({"-o", picture.string(), "--mode", "surface"});
    EXPECT_EQ(refused.exitCode, 1);
    EXPECT_EQ(refused.err, "subscan: " + notes.string() +
                               ": --export-buffers replaces the files of an earlier export in its "
                               "folder, and this is none of them; give --export-buffers a new or "
                               "empty folder\n");
    EXPECT_EQ(test::fileBytes(notes), "mine");
    EXPECT_FALSE(std::filesystem::exists(picture));
    EXPECT_FALSE(std::filesystem::exists(exported / "normals.pfm"));
}

TEST(RenderCommandGLTest, AModesOwnOptionsInAnotherModeAreNamed) {
    // Accepted and ignored without a word (found by an outside test); drawn, with a warning,
    // since --save-settings keeps them for the other modes.
    const test::TempDir dir;
    const std::string out = (dir / "x.png").string();
    auto render = [&](const std::vector<std::string>& options) {
        return test::renderSmallSphere(out, options);
    };
    const test::CommandResult material = render({"--mode", "surface", "--material", "skin1"});
    EXPECT_EQ(material.exitCode, 0) << material.err;
    EXPECT_THAT(material.err,
                HasSubstr("--material sets the subsurface scattering of the sss mode: it has no "
                          "effect on the surface mode's picture"));
    const test::CommandResult size = render({"--mode", "points", "--point-size", "4"});
    EXPECT_EQ(size.exitCode, 0) << size.err;
    EXPECT_THAT(size.err, HasSubstr("--point-size is the splats' size"));
    const test::CommandResult used =
        render({"--mode", "sss", "--material", "skin1", "--point-size", "4"});
    EXPECT_EQ(used.exitCode, 0) << used.err;
    EXPECT_THAT(used.err, ::testing::Not(HasSubstr("--material")));
}

/// The RGB of pixel i of a 3-channel PFM.
std::array<float, 3> rgbAt(const ImageF& image, std::size_t i) {
    return {image.values[3 * i], image.values[3 * i + 1], image.values[3 * i + 2]};
}

TEST(RenderCommandGLTest, SingleScatteringExportsItsTermAndCoefficients) {
    const test::TempDir dir;
    const std::string scan = "synthetic:sphere?points=20000";
    const std::vector<std::string> view{"--width", "48", "--height", "40", "--unit", "cm"};
    auto render = [&](const std::string& name, std::vector<std::string> extra) {
        std::vector<std::string> arguments{"render",
                                           scan,
                                           "-o",
                                           (dir / (name + ".png")).string(),
                                           "--export-buffers",
                                           (dir / name).string()};
        arguments.insert(arguments.end(), view.begin(), view.end());
        arguments.insert(arguments.end(), extra.begin(), extra.end());
        const auto result = runSubscan(arguments);
        EXPECT_EQ(result.exitCode, 0) << result.err;
    };
    render("surface", {"--mode", "surface"});
    render("single", {"--mode", "sss", "--scattering", "single", "--coefficients", "material",
                      "--material", "skin2"});
    render("gaussian", {"--mode", "sss"});
    for (const char* file : {"single.pfm", "sigma_s.pfm", "sigma_a.pfm"}) {
        EXPECT_TRUE(std::filesystem::exists(dir / "single" / file)) << file;
        EXPECT_FALSE(std::filesystem::exists(dir / "gaussian" / file)) << file;
    }
    const ImageF surface = readPfm(dir / "surface" / "radiance.pfm");
    const ImageF radiance = readPfm(dir / "single" / "radiance.pfm");
    const ImageF single = readPfm(dir / "single" / "single.pfm");
    const ImageF sigmaS = readPfm(dir / "single" / "sigma_s.pfm");
    const ImageF sigmaA = readPfm(dir / "single" / "sigma_a.pfm");
    const ImageF depth = readPfm(dir / "single" / "depth.pfm");
    ASSERT_EQ(single.values.size(), radiance.values.size());
    // skin2 (Jensen et al. 2001), mm⁻¹.
    const std::array<float, 3> skinSigmaS{1.09f, 1.59f, 1.79f}, skinSigmaA{0.013f, 0.070f, 0.145f};
    int covered = 0;
    for (std::size_t i = 0; i < depth.values.size(); ++i) {
        const bool surfacePixel = !std::isinf(depth.values[i]);
        covered += surfacePixel ? 1 : 0;
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(rgbAt(sigmaS, i)[c], surfacePixel ? skinSigmaS[c] : 0.0f) << i;
            EXPECT_EQ(rgbAt(sigmaA, i)[c], surfacePixel ? skinSigmaA[c] : 0.0f) << i;
            // radiance.pfm is the surface mode's radiance plus single scattering: the same
            // reconstruction and shading, so they differ by the half-float roundings of two
            // images (2^-11 of each).
            const float expected = rgbAt(surface, i)[c] + rgbAt(single, i)[c];
            EXPECT_NEAR(rgbAt(radiance, i)[c], expected, 2e-3f * expected + 1e-6f) << i;
            EXPECT_EQ(rgbAt(single, i)[c] > 0.0f, surfacePixel) << i << " channel " << c;
        }
    }
    EXPECT_GT(covered, 300);  // the sphere fills about half of 48x40
}

}  // namespace
}  // namespace subscan
