// The viewer's loading of a scan read whole (ScanLoadJob): it comes provisional, with h from a
// sample, so that its first picture shows at once; its local spacing and normals follow
// (completeSpacing) without changing h.
#include "app/viewer/ScanLoadJob.h"

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "core/LocalSpacing.h"
#include "render/Renderer.h"
#include "support/TestSupport.h"

namespace subscan::viewer {
namespace {

TEST(ScanLoadJobTest, AWholeScanComesProvisionalAndCompletesWithTheSameH) {
    SUBSCAN_REQUIRE_TEST_DATA(data);
    ScanLoadJob job((data / "bun_zipper.ply").string(), StreamingSettings{});
    for (int wait = 0; wait < 60'000 && !job.finished(); ++wait) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ASSERT_TRUE(job.finished());
    const PreparedScan prepared = job.take();
    const PointCloud& cloud = prepared.scan.cloud;
    ASSERT_FALSE(cloud.hasNormals());
    EXPECT_TRUE(prepared.provisional);
    EXPECT_TRUE(prepared.spacing.local.empty());
    EXPECT_TRUE(prepared.packed.normals.empty());
    EXPECT_TRUE(prepared.packed.localSpacing.halves.empty());
    EXPECT_EQ(prepared.spacing.global, sampleSpacing(cloud).h);

    const std::optional<CompletedSpacing> completed =
        completeSpacing(cloud, prepared.sample, [] { return false; });
    ASSERT_TRUE(completed);
    // What the whole scan's renderer would estimate at once, and h unchanged: the picture does
    // not jump to another h when the rest arrives.
    const PointSpacing expected = estimatePointSpacing(cloud);
    EXPECT_EQ(completed->spacing.global, prepared.spacing.global);
    EXPECT_EQ(completed->spacing.local, expected.local);
    EXPECT_EQ(completed->packed.localSpacing.halves, packLocalSpacing(expected.local).halves);
    EXPECT_EQ(completed->packed.normals, packNormals(normalsFor(cloud, NormalSource::Auto)));
    EXPECT_EQ(completed->packed.normals.size(), cloud.size());  // estimated: it has none

    EXPECT_FALSE(completeSpacing(cloud, prepared.sample, [] { return true; }));
}

}  // namespace
}  // namespace subscan::viewer
