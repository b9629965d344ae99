#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "render/GpuPointCloud.h"
#include "render/RenderSettings.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

TEST(RenderSettingsTest, JsonRoundTripAndPartialFiles) {
    RasterSettings settings;
    settings.mode = RenderMode::Splats;
    settings.path = RasterPath::TwoPass32;
    settings.pointSize = 6;
    settings.backgroundSrgb = {0.1f, 0.2f, 0.3f};
    settings.timing = TimingMode::FinishAndClock;
    settings.resolution = Resolution::Half;
    const RasterSettings back = nlohmann::json(settings).get<RasterSettings>();
    EXPECT_EQ(back.mode, settings.mode);
    EXPECT_EQ(back.path, settings.path);
    EXPECT_EQ(back.pointSize, settings.pointSize);
    EXPECT_EQ(back.backgroundSrgb, settings.backgroundSrgb);
    EXPECT_EQ(back.timing, settings.timing);
    EXPECT_EQ(back.resolution, settings.resolution);

    const RasterSettings partial = nlohmann::json{{"point_size", 3}}.get<RasterSettings>();
    EXPECT_EQ(partial.pointSize, 3);
    EXPECT_EQ(partial.mode, RasterSettings{}.mode);
}

TEST(RenderSettingsTest, WholeSettingsRoundTripThroughAFile) {
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    settings.raster.stage = Stage::Normals;
    settings.surface.visibilityThreshold = 0.3f;
    settings.surface.edgeRule = false;
    settings.surface.restrictToPoints = false;
    settings.shading.lights.push_back({{1, 2, 3}, {0.5f, 0.5f, 0.5f}});
    const test::TempDir dir;
    writeSettingsFile(dir / "s.json", settings);
    const RenderSettings back = readSettingsFile(dir / "s.json");
    EXPECT_EQ(back.raster.mode, RenderMode::Surface);
    EXPECT_EQ(back.raster.stage, Stage::Normals);
    EXPECT_EQ(back.surface.visibilityThreshold, 0.3f);
    EXPECT_FALSE(back.surface.edgeRule);
    EXPECT_FALSE(back.surface.restrictToPoints);
    ASSERT_EQ(back.shading.lights.size(), 1u);
    EXPECT_EQ(back.shading.lights[0].direction, glm::vec3(1, 2, 3));
    const auto bad = dir.write("bad.json", R"({"surface": {"fill_directions": 9}})");
    try {
        readSettingsFile(bad);
        FAIL() << "accepted";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr("'fill_directions' = 9 is outside 1..8"));
    }
    const auto unknown = dir.write("unknown.json", R"({"surfaces": {}})");
    EXPECT_THROW(readSettingsFile(unknown), Error);
}

TEST(RenderSettingsTest, ResolutionIsFullUnlessAsked) {
    EXPECT_EQ(RenderSettings{}.raster.resolution, Resolution::Full);
    const test::TempDir dir;
    const auto half = dir.write("half.json", R"({"raster": {"resolution": "half"}})");
    EXPECT_EQ(readSettingsFile(half).raster.resolution, Resolution::Half);
    const auto bad = dir.write("bad.json", R"({"raster": {"resolution": "quarter"}})");
    try {
        readSettingsFile(bad);
        FAIL() << "accepted";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr("quarter"));
    }
}

TEST(RenderSettingsTest, ScatteringSettingsRoundTripAndCheckTheMaterial) {
    RenderSettings settings;
    settings.raster.mode = RenderMode::Sss;
    settings.scattering.material = "skin-deon";
    settings.scattering.unit = SceneUnit::Inch;
    settings.scattering.scale = 2.5f;
    settings.scattering.albedo = AlbedoPlacement::PreScatter;
    settings.scattering.maxTaps = 9;
    const RenderSettings back = nlohmann::json(settings).get<RenderSettings>();
    EXPECT_EQ(back.raster.mode, RenderMode::Sss);
    EXPECT_EQ(back.scattering.material, "skin-deon");
    EXPECT_EQ(back.scattering.unit, SceneUnit::Inch);
    EXPECT_EQ(back.scattering.scale, 2.5f);
    EXPECT_EQ(back.scattering.albedo, AlbedoPlacement::PreScatter);
    EXPECT_EQ(back.scattering.maxTaps, 9);
    try {
        nlohmann::json({{"material", "jade"}}).get<ScatteringSettings>();
        FAIL() << "accepted an unknown material";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr("no material 'jade'"));
        EXPECT_THAT(error.what(), ::testing::HasSubstr("marble-jimenez"));
    }
    EXPECT_THROW(nlohmann::json({{"unit", "furlong"}}).get<ScatteringSettings>(), Error);
    EXPECT_THROW(nlohmann::json({{"scale", -1}}).get<ScatteringSettings>(), Error);
    EXPECT_DOUBLE_EQ(millimetresPerUnit(SceneUnit::Inch), 25.4);
    EXPECT_DOUBLE_EQ(millimetresPerUnit(SceneUnit::Metre), 1000.0);
}

TEST(RenderSettingsTest, BadValuesAreNamed) {
    EXPECT_THROW(nlohmann::json({{"mode", "voxels"}}).get<RasterSettings>(), Error);
    EXPECT_THROW(nlohmann::json({{"point_size", 0}}).get<RasterSettings>(), Error);
    EXPECT_THROW(nlohmann::json({{"background_srgb", {2, 0, 0}}}).get<RasterSettings>(), Error);
    try {
        parseRenderMode("voxels");
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr("points, points-gl, splats, surface"));
    }
}

TEST(RenderSettingsTest, DisplayColorsUseColourThenIntensityThenGrey) {
    PointCloud cloud;
    cloud.positions.resize(3);
    cloud.colors = {{1, 2, 3, 255}, {4, 5, 6, 255}, {7, 8, 9, 255}};
    EXPECT_EQ(displayColors(cloud)[1], 4u | 5u << 8 | 6u << 16 | 255u << 24);
    cloud.colors.clear();
    cloud.intensities = {0.0f, 50.0f, 100.0f};
    const auto grey = displayColors(cloud);
    EXPECT_LT(grey[0] & 0xFF, grey[1] & 0xFF);  // brighter with intensity
    EXPECT_LT(grey[1] & 0xFF, grey[2] & 0xFF);
    cloud.intensities.clear();
    EXPECT_EQ(displayColors(cloud)[2] & 0xFFFFFF, 200u | 200u << 8 | 200u << 16);
}

}  // namespace
}  // namespace subscan
