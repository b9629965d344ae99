// The reconstruction of the Stanford bunny's 35,947 vertices against its mesh, at the targets
// of the issue. 512x512 with 8 views (the acceptance run uses 1024x1024; bench/README.md has
// both): the surface still spans ~250k pixels per view, and the test takes a few seconds.
#include <gtest/gtest.h>

#include "core/Srgb.h"
#include "eval/Evaluation.h"
#include "io/ScanLoader.h"
#include "support/GlTestSupport.h"
#include "support/QualityTargets.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

TEST(BunnyEvaluationDataTest, VerticesAsPointsMeetTheTargets) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    const LoadedScan mesh = loadScan((data / "bun_zipper.ply").string());
    const auto truth = makeMeshScene(mesh.cloud, AlbedoSource::Grey);
    PointCloud points = mesh.cloud;
    points.triangles.clear();
    points.intensities.clear();
    points.colors.assign(points.size(), srgb8Color(glm::vec3(0.7f)));  // the mesh's grey
    EvaluationSettings settings;
    settings.views = 8;
    settings.width = 512;
    settings.height = 512;
    const EvaluationReport report =
        evaluate(test::glTestContext(), *truth, points, settings, RenderSettings{});
    test::expectQualityTargets(report);
}

}  // namespace
}  // namespace subscan
