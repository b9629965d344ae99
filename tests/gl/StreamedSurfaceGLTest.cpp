// A streamed survey's surface where its levels of detail meet: a large flat plane seen at a
// grazing angle loads deep nodes near the eye and coarse ones far away, and must still be one
// closed surface on the true plane, with no step where a node ends.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <numbers>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>
#include <glm/matrix.hpp>

#include "core/Camera.h"
#include "core/LocalSpacing.h"
#include "core/PointCloud.h"
#include "eval/GroundTruth.h"
#include "io/PointRecordSource.h"
#include "io/TemporaryFolder.h"
#include "lod/CopcWriter.h"
#include "lod/NodeSelection.h"
#include "lod/NodeSource.h"
#include "lod/OctreeIndexer.h"
#include "render/Renderer.h"
#include "support/GlTestSupport.h"
#include "support/TestScenes.h"

namespace subscan {
namespace {

constexpr double kHalfExtent = 40.0;  // metres: an 80 m square
constexpr double kGridSpacing = 0.1;  // 640,000 points

/// The plane as a scan: a grid jittered by up to a third of its spacing, so that no level's
/// sample lines up in rows.
PointCloud planePoints() {
    PointCloud cloud;
    std::mt19937 random(7);
    std::uniform_real_distribution<float> jitter(-kGridSpacing / 3, kGridSpacing / 3);
    const int side = static_cast<int>(2 * kHalfExtent / kGridSpacing);
    for (int i = 0; i < side; ++i) {
        for (int j = 0; j < side; ++j) {
            const float x = static_cast<float>(-kHalfExtent + (i + 0.5) * kGridSpacing);
            const float z = static_cast<float>(-kHalfExtent + (j + 0.5) * kGridSpacing);
            cloud.positions.emplace_back(x + jitter(random), 0.0f, z + jitter(random));
            cloud.bounds.add(glm::dvec3(cloud.positions.back()));
        }
    }
    return cloud;
}

/// A 320x240 camera at `eye` looking along `direction`, Y up.
Camera lookingFrom(const glm::dvec3& eye, const glm::dvec3& direction, double fovyDegrees) {
    Camera camera;
    camera.width = 320;
    camera.height = 240;
    camera.fovyDegrees = fovyDegrees;
    camera.nearPlane = 0.1;
    camera.farPlane = 500.0;
    camera.view = glm::lookAt(eye, eye + direction, glm::dvec3(0.0, 1.0, 0.0));
    return camera;
}

/// A view from above the plane's near edge along it, and the budget that makes its levels.
struct GrazingView {
    const char* what;
    double heightMetres, pitchDegrees, fovyDegrees;
    std::uint64_t budget;
    std::size_t levels;  // the finest levels on the checked part, at least
};

// The ground runs from about 8 m to the far edge 80 m away, where it is steeper on screen than
// the reconstruction keeps a surface (the pull's slope): the checks leave that out.
constexpr GrazingView kViews[] = {
    // Level 2 near the eye on one side of the octree's middle (x = 0), level 1 on the other:
    // the border runs down the picture where the points lie 5 and 9 pixels apart.
    {"a border between levels 1 and 2 near the eye", 6.0, 20.0, 60.0, 70'000, 2},
    // Levels 2, 1 and 0 from near to far across the picture.
    {"three levels from near to far", 10.0, 35.0, 80.0, 100'000, 3},
};

/// Renders `view` of the plane streamed from `source` within its budget and checks that the
/// surface has no hole and no step where the levels meet.
void checkGrazingView(const lod::NodeSource& source, const GrazingView& view) {
    const double pitch = view.pitchDegrees * std::numbers::pi / 180.0;
    const Camera camera =
        lookingFrom(glm::dvec3(0.0, view.heightMetres, kHalfExtent - 1.0),
                    glm::dvec3(0.0, -std::sin(pitch), -std::cos(pitch)), view.fovyDegrees);

    const std::vector<std::size_t> nodes = lod::selectNodes(source, camera, view.budget);
    const LoadedScan scan = lod::loadStreamedScan(source, nodes);
    EXPECT_LT(scan.cloud.size(), source.info().points / 3);
    // The level of the finest selected node that holds a point of the plane: its points' spacing
    // there. -1 where none does.
    std::vector<bool> selected(source.nodes().size(), false);
    for (const std::size_t node : nodes) {
        selected[node] = true;
    }
    const lod::OctreeCube& cube = source.info().cube;
    const auto finestLevelAt = [&](const glm::dvec3& position) {
        for (int level = 20; level >= 0; --level) {
            const std::size_t node = source.find(lod::nodeKeyAt(cube, position, level));
            if (node < selected.size() && selected[node]) {
                return level;
            }
        }
        return -1;
    };

    Renderer renderer(test::glTestContext(), scan.cloud,
                      estimatePointSpacing(scan.cloud, scan.levelSpacing));
    renderer.prepareNormals(scan.cloud, streamedNormals(NormalSource::Auto));
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    ASSERT_EQ(renderer.render(camera, settings, FrameOutputs::Everything).divisor, 1);
    const std::vector<float> depth = renderer.resources().texture("surfaceDepth").readFloats();
    const GroundTruthImages truth = renderGroundTruth(test::GroundRectangle(kHalfExtent), camera);
    ASSERT_EQ(depth.size(), truth.depth.size());

    const int width = camera.width, height = camera.height;
    const auto at = [&](int x, int y) { return static_cast<std::size_t>(y * width + x); };
    const double focal = camera.focalLengthPixels();
    // The spacing of the points where `level` is the finest selected: the union of the levels
    // down to it samples the plane at the root spacing / 2^level, or at the grid's if finer.
    const auto spacingOn = [&](int level) {
        return std::max(kGridSpacing, cube.rootSpacing / std::exp2(level));
    };
    std::vector<int> levels(depth.size(), -1);
    const glm::dmat4 toFile = glm::inverse(camera.view);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            if (std::isfinite(truth.depth[at(x, y)])) {
                const glm::dvec3 inView =
                    double{truth.depth[at(x, y)]} * pixelCentreDirection(camera, x, y);
                // On the plane exactly: the octree's middle, y = 0, parts its nodes there.
                glm::dvec3 onPlane(toFile * glm::dvec4(inView, 1.0));
                onPlane.y = 0.0;
                levels[at(x, y)] = finestLevelAt(onPlane);
            }
        }
    }
    // Checked: the truth covers every pixel within 2 or twice the points' spacing there,
    // whichever is more, and these lie in the picture (a
    // level keeps a point of each of its cells, anywhere in it, so its outermost points lie up
    // to a spacing inside the true outline, and the outline between them cuts in further);
    // and the plane is no steeper there than the reconstruction keeps.
    const auto checked = [&](int x, int y) {
        const std::size_t i = at(x, y);
        if (levels[i] < 0) {
            return false;
        }
        const int margin = std::max(
            2, static_cast<int>(std::ceil(2.0 * spacingOn(levels[i]) * focal / truth.depth[i])));
        for (int dy = -margin; dy <= margin; ++dy) {
            for (int dx = -margin; dx <= margin; ++dx) {
                const int nx = x + dx, ny = y + dy;
                if (nx < 0 || ny < 0 || nx >= width || ny >= height ||
                    std::isinf(truth.depth[at(nx, ny)])) {
                    return false;
                }
            }
        }
        // Below the cap by more than float rounding: a capped pixel is steeper.
        return truth.depthWithinPixel[i] <
               0.999 * kSteepestDepthWithinPixel * truth.depth[i] / focal;
    };
    // How far the surface lies behind (+) or before the true plane where it covers.
    const auto offPlane = [&](int x, int y) {
        return static_cast<double>(depth[at(x, y)]) - truth.depth[at(x, y)];
    };
    int interior = 0, holes = 0, pairs = 0, steps = 0, borders = 0, borderSteps = 0;
    double largestStep = 0.0;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            if (!checked(x, y)) {
                continue;
            }
            ++interior;
            if (std::isinf(depth[at(x, y)])) {
                ++holes;
                continue;
            }
            for (const auto& [nx, ny] : {std::pair{x + 1, y}, std::pair{x, y + 1}}) {
                if (nx >= width || ny >= height || !checked(nx, ny) ||
                    std::isinf(depth[at(nx, ny)])) {
                    continue;
                }
                ++pairs;
                // Neighbours may differ by the plane's depths within each pixel (a point's own
                // depth stands for its pixel, the truth is the centre's) and by h, the scan's
                // spacing (every point lies on the plane; the fill between them, interpolated
                // in the picture, bends off it by a little). A seam between levels (a level's
                // points misplaced, or its surface not meeting the next's) would be a step
                // beyond that.
                const double step = std::abs(offPlane(x, y) - offPlane(nx, ny));
                const double allowed = kGridSpacing + truth.depthWithinPixel[at(x, y)] +
                                       truth.depthWithinPixel[at(nx, ny)];
                const bool border = levels[at(x, y)] != levels[at(nx, ny)];
                borders += border;
                steps += step > allowed;
                borderSteps += border && step > allowed;
                largestStep = std::max(largestStep, step / allowed);
            }
        }
    }
    // The checks must see node borders: several levels meet on the checked part.
    std::vector<int> seen;
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const int level = levels[at(x, y)];
            if (checked(x, y) && std::find(seen.begin(), seen.end(), level) == seen.end()) {
                seen.push_back(level);
            }
        }
    }
    EXPECT_GE(seen.size(), view.levels) << "finest levels on the checked part";
    EXPECT_GT(borders, width / 2) << "pixel pairs across a node border";
    ASSERT_GT(interior, width * height / 3);
    EXPECT_EQ(holes, 0) << "of " << interior << " pixels inside the outline";
    EXPECT_EQ(borderSteps, 0) << "of " << borders << " neighbours across node borders";
    EXPECT_EQ(steps, 0) << "of " << pairs << " neighbours; the largest step is " << largestStep
                        << " of what is allowed";
}

/// The plane indexed into a COPC file once for the tests of this file (gtest's suite set-up:
/// a second of indexing, not two).
class StreamedSurfaceGLTest : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        folder_ = std::make_unique<TemporaryFolder>(std::filesystem::temp_directory_path(),
                                                    "subscan-test");
        lod::IndexSettings index;
        index.temporaryDirectory = folder_->path();
        lod::writeCopc(*cloudRecordSource(planePoints(), "the plane"),
                       folder_->path() / "plane.copc.laz", index);
        source_ = lod::openCopc(folder_->path() / "plane.copc.laz");
    }
    static void TearDownTestSuite() {
        source_.reset();  // closed before its folder goes
        folder_.reset();
    }
    static inline std::unique_ptr<TemporaryFolder> folder_;
    static inline std::unique_ptr<lod::NodeSource> source_;
};

TEST_F(StreamedSurfaceGLTest, AGrazingPlaneIsOneSurfaceAcrossItsLevelsOfDetail) {
    for (const GrazingView& view : kViews) {
        SCOPED_TRACE(view.what);
        checkGrazingView(*source_, view);
    }
}

TEST_F(StreamedSurfaceGLTest, SeveralViewsTakeEveryNodeEachOfThemTakes) {
    // A turntable's selection (no GL): from the plane's middle, 6 m up, looking out four ways.
    // One set for all the views holds each view's own nodes where the budget allows, and
    // keeps to the budget where it does not.
    std::vector<Camera> cameras;
    for (int turn = 0; turn < 4; ++turn) {
        const double yaw = turn * std::numbers::pi / 2.0;
        cameras.push_back(lookingFrom(glm::dvec3(0.0, 6.0, 0.0),
                                      glm::dvec3(std::sin(yaw), -0.4, std::cos(yaw)), 60.0));
    }
    const std::uint64_t every = source_->info().points;
    const std::vector<std::size_t> all = lod::selectNodes(*source_, cameras, every);
    std::size_t largestSingle = 0;
    for (const Camera& camera : cameras) {
        const std::vector<std::size_t> single = lod::selectNodes(*source_, camera, every);
        largestSingle = std::max(largestSingle, single.size());
        for (const std::size_t node : single) {
            EXPECT_NE(std::find(all.begin(), all.end(), node), all.end()) << "node " << node;
        }
    }
    EXPECT_GT(all.size(), largestSingle);  // the views differ: the union is larger
    EXPECT_EQ(lod::selectNodes(*source_, std::span(cameras).first(1), 70'000),
              lod::selectNodes(*source_, cameras[0], 70'000));
    std::uint64_t taken = 0;
    for (const std::size_t node : lod::selectNodes(*source_, cameras, 70'000)) {
        taken += source_->nodes()[node].pointCount;
    }
    EXPECT_LE(taken, 70'000u);
}

}  // namespace
}  // namespace subscan
