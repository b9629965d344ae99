#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <glm/ext/matrix_transform.hpp>

#include "core/Error.h"
#include "lod/NodeSelection.h"
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
    settings.colorBlend = 0.01f;
    settings.normalBlend = 2.5f;
    const RasterSettings back = nlohmann::json(settings).get<RasterSettings>();
    EXPECT_EQ(back, settings);
    EXPECT_EQ(back.mode, settings.mode);
    EXPECT_EQ(back.path, settings.path);
    EXPECT_EQ(back.pointSize, settings.pointSize);
    EXPECT_EQ(back.backgroundSrgb, settings.backgroundSrgb);
    EXPECT_EQ(back.timing, settings.timing);
    EXPECT_EQ(back.resolution, settings.resolution);

    const RasterSettings partial = nlohmann::json{{"point_size", 3}}.get<RasterSettings>();
    EXPECT_EQ(partial.pointSize, 3);
    EXPECT_EQ(partial.mode, RasterSettings{}.mode);
    EXPECT_EQ(partial.normalBlend, 1.0f);  // the measured default (docs/pipeline.md)
    EXPECT_THROW(nlohmann::json({{"normal_blend", -1.0}}).get<RasterSettings>(), Error);
    EXPECT_THROW(nlohmann::json({{"normal_blend", 17.0}}).get<RasterSettings>(), Error);
}

TEST(RenderSettingsTest, TemporalSettingsRoundTripAndRefuseImpossibleValues) {
    RenderSettings settings;
    settings.temporal = {true, 0.2f, 1.5f, 64};
    const RenderSettings back = nlohmann::json(settings).get<RenderSettings>();
    EXPECT_EQ(back.temporal, settings.temporal);
    EXPECT_EQ(back, settings);
    auto read = [](const nlohmann::json& temporal) {
        return nlohmann::json{{"temporal", temporal}}.get<RenderSettings>();
    };
    EXPECT_THROW(read({{"new_frame_weight", 0.0}}), Error);  // the new frame would never count
    EXPECT_THROW(read({{"max_frames", 4096}}), Error);       // beyond a half float's integers
    EXPECT_THROW(read({{"clip", 1.0}}), Error);              // unknown key
    EXPECT_FALSE(read(nlohmann::json::object()).temporal.enabled);
}

TEST(RenderSettingsTest, StreamingSettingsRoundTripAndRefuseImpossibleValues) {
    RenderSettings settings;
    EXPECT_EQ(settings.streaming.lod, lod::LodMode::Auto);
    EXPECT_EQ(settings.streaming.pointBudget, 0u);  // the renderer's default
    settings.streaming.lod = lod::LodMode::Off;
    settings.streaming.pointBudget = 2'500'000;
    EXPECT_EQ(settings.streaming.nodeCacheMegabytes, 512u);
    settings.streaming.nodeCacheMegabytes = 100;
    EXPECT_EQ(settings.streaming.uploadMegabytesPerFrame, 32u);
    settings.streaming.uploadMegabytesPerFrame = 8;
    const nlohmann::json json = settings;
    EXPECT_EQ(json["streaming"]["lod"], "off");
    EXPECT_EQ(json["streaming"]["point_budget"], 2'500'000);
    EXPECT_EQ(json["streaming"]["node_cache_megabytes"], 100);
    EXPECT_EQ(json["streaming"]["upload_megabytes_per_frame"], 8);
    EXPECT_EQ(json.get<RenderSettings>(), settings);
    const auto refusal = [](const nlohmann::json& streaming) {
        return test::errorMessage([&] {
            (void)nlohmann::json{{"streaming", streaming}}.get<RenderSettings>();
        });
    };
    EXPECT_THAT(refusal({{"lod", "sometimes"}}),
                ::testing::HasSubstr("'sometimes' is not a level-of-detail"));
    EXPECT_THAT(refusal({{"point_budget", -1}}), ::testing::HasSubstr("'point_budget'"));
    EXPECT_THAT(refusal({{"point_budget", 2e12}}), ::testing::HasSubstr("'point_budget'"));
    EXPECT_THAT(refusal({{"budget", 5}}), ::testing::HasSubstr("budget"));
    EXPECT_THAT(refusal({{"node_cache_megabytes", 4}}),
                ::testing::HasSubstr("'node_cache_megabytes'"));
    EXPECT_THAT(refusal({{"upload_megabytes_per_frame", 0}}),
                ::testing::HasSubstr("'upload_megabytes_per_frame'"));
    EXPECT_EQ(lod::pointBudgetFor(0, true), lod::kSoftwarePointBudget);
    EXPECT_EQ(lod::pointBudgetFor(0, false), lod::kHardwarePointBudget);
    EXPECT_EQ(lod::pointBudgetFor(5, true), 5u);
}

TEST(RenderSettingsTest, WholeSettingsRoundTripThroughAFile) {
    RenderSettings settings;
    settings.raster.mode = RenderMode::Surface;
    settings.raster.stage = Stage::Normals;
    settings.surface.visibilityThreshold = 0.3f;
    settings.surface.edgeRule = false;
    settings.surface.restrictToPoints = false;
    settings.surface.localSpacing = false;
    settings.shading.lights.push_back({{1, 2, 3}, {0.5f, 0.5f, 0.5f}});
    const test::TempDir dir;
    writeSettingsFile(dir / "s.json", settings);
    const RenderSettings back = readSettingsFile(dir / "s.json");
    EXPECT_EQ(back.raster.mode, RenderMode::Surface);
    EXPECT_EQ(back.raster.stage, Stage::Normals);
    EXPECT_EQ(back.surface.visibilityThreshold, 0.3f);
    EXPECT_FALSE(back.surface.edgeRule);
    EXPECT_FALSE(back.surface.restrictToPoints);
    EXPECT_FALSE(back.surface.localSpacing);
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
        FAIL() << "accepted the mode 'voxels'";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), ::testing::HasSubstr("points, points-gl, splats, surface"));
    }
}

TEST(RenderSettingsTest, NumbersAreCheckedBeforeTheyBecomeTheSettingsType) {
    const auto refusal = [](const nlohmann::json& json) {
        return test::errorMessage([&] { (void)json.get<RenderSettings>(); });
    };
    // -1 wrapped around to 2^64 - 1 in an unsigned setting, and 2.5 lost its half.
    EXPECT_THAT(refusal({{"streaming", {{"node_cache_megabytes", -1}}}}),
                ::testing::HasSubstr("'node_cache_megabytes' = -1 is outside"));
    EXPECT_THAT(refusal({{"temporal", {{"max_frames", 2.5}}}}),
                ::testing::HasSubstr("'max_frames' = 2.5 is not a whole number"));
    EXPECT_THAT(refusal({{"temporal", {{"max_frames", "8"}}}}),
                ::testing::HasSubstr("'max_frames' has the wrong type"));
    EXPECT_THAT(refusal({{"temporal", {{"max_frames", true}}}}),
                ::testing::HasSubstr("'max_frames' has the wrong type"));
    // Beyond a float's range: refused before any cast to float.
    EXPECT_THAT(refusal({{"raster", {{"point_size", 1e39}}}}),
                ::testing::HasSubstr("'point_size' = 1e+39 is outside"));
    // A float setting at its bound as the file writes it (0.01, not 0.01f) is inside.
    const nlohmann::json atBound = {{"temporal", {{"new_frame_weight", 0.01}}}};
    EXPECT_FLOAT_EQ(atBound.get<RenderSettings>().temporal.newFrameWeight, 0.01f);
    // A number beyond a double's range in a settings file: one sentence naming the file.
    const test::TempDir dir;
    const auto file = dir.write("huge.json", R"({"surface": {"fill_radius": 1e400}})");
    EXPECT_THAT(test::errorMessage([&] { (void)readSettingsFile(file); }),
                ::testing::HasSubstr("huge.json: not valid JSON: a number beyond"));
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

namespace subscan {
namespace {

/// The message of the subscan::Error that reading `json` as a settings file throws.
std::string settingsError(const std::string& json) {
    const test::TempDir dir;
    const auto file = dir.write("settings.json", json);
    try {
        readSettingsFile(file);
    } catch (const Error& error) {
        const std::string message = error.what();
        EXPECT_THAT(message, ::testing::HasSubstr(file.string())) << "the file is named";
        return message;
    }
    ADD_FAILURE() << "accepted " << json;
    return {};
}

TEST(RenderSettingsTest, SingleScatteringSettingsRoundTrip) {
    RenderSettings settings;
    ScatteringSettings& scattering = settings.scattering;
    scattering.method = ScatteringMethod::Both;
    scattering.coefficients = CoefficientSource::Material;
    scattering.material = "skin1";
    scattering.meanFreePathMm = {1.0f, 2.0f, 3.0f};
    scattering.eta = 1.45f;
    scattering.phaseG = -0.25f;
    scattering.singleSamples = 12;
    const ScatteringSettings back = nlohmann::json(settings).get<RenderSettings>().scattering;
    EXPECT_EQ(back.method, ScatteringMethod::Both);
    EXPECT_EQ(back.coefficients, CoefficientSource::Material);
    EXPECT_EQ(back.meanFreePathMm, glm::vec3(1.0f, 2.0f, 3.0f));
    ASSERT_TRUE(back.eta.has_value());
    EXPECT_EQ(*back.eta, 1.45f);
    EXPECT_EQ(back.phaseG, -0.25f);
    EXPECT_EQ(back.singleSamples, 12);
    // Unset η is written as null and read back unset: the material's η.
    scattering.eta.reset();
    EXPECT_FALSE(nlohmann::json(settings).get<RenderSettings>().scattering.eta.has_value());
}

TEST(RenderSettingsTest, EtaIsTheMaterialsUnlessSet) {
    ScatteringSettings settings;
    settings.material = "marble";
    EXPECT_DOUBLE_EQ(scatteringEta(settings), 1.5);
    settings.material = "skin1";
    EXPECT_DOUBLE_EQ(scatteringEta(settings), 1.3);
    settings.eta = 1.7f;
    EXPECT_DOUBLE_EQ(scatteringEta(settings), 1.7f);
}

TEST(RenderSettingsTest, DefaultsKeepTheGaussianPathAndColourCoefficients) {
    const ScatteringSettings settings;
    EXPECT_EQ(settings.method, ScatteringMethod::Gaussian);
    EXPECT_EQ(settings.coefficients, CoefficientSource::Color);
    EXPECT_EQ(settings.phaseG, 0.0f);
    EXPECT_FALSE(settings.eta.has_value());
}

TEST(RenderSettingsTest, AnUnknownKeyInAnySectionIsNamed) {
    EXPECT_THAT(settingsError(R"({"scattering": {"metod": "single"}})"),
                ::testing::HasSubstr("unknown setting 'metod' in 'scattering'"));
    EXPECT_THAT(settingsError(R"({"raster": {"mdoe": "sss"}})"),
                ::testing::HasSubstr("unknown setting 'mdoe' in 'raster'"));
    EXPECT_THAT(settingsError(R"({"surface": {"fill_radiu": 2}})"),
                ::testing::HasSubstr("unknown setting 'fill_radiu' in 'surface'"));
    EXPECT_THAT(settingsError(R"({"shading": {"lite": []}})"),
                ::testing::HasSubstr("unknown setting 'lite' in 'shading'"));
    EXPECT_THAT(
        settingsError(R"({"shading": {"lights": [{"direction": [0, 1, 0], "color": [1, 1, 1]}]}})"),
        ::testing::HasSubstr("unknown setting 'color' in 'lights'"));
    EXPECT_THAT(settingsError(R"({"scattering": []})"),
                ::testing::HasSubstr("the settings section 'scattering' must be a JSON object"));
    // A key given twice: the last used to win without a word.
    EXPECT_THAT(settingsError(R"({"raster": {"mode": "surface", "mode": "points"}})"),
                ::testing::HasSubstr("the key 'mode' appears twice in one object"));
    EXPECT_THAT(settingsError(R"({"raster": {}, "raster": {"mode": "points"}})"),
                ::testing::HasSubstr("the key 'raster' appears twice"));
    // The same key in two objects is no repetition.
    const test::TempDir dir;
    EXPECT_NO_THROW(readSettingsFile(dir.write(
        "two.json",
        R"({"shading": {"lights": [{"direction": [0, 1, 0]}, {"direction": [1, 0, 0]}]}})")));
}

TEST(RenderSettingsTest, ImpossibleScatteringValuesAreNamed) {
    EXPECT_THAT(settingsError(R"({"scattering": {"method": "double"}})"),
                ::testing::HasSubstr("'double' is not a scattering method (expected one of: "
                                     "gaussian, single, both)"));
    EXPECT_THAT(settingsError(R"({"scattering": {"coefficients": "scan"}})"),
                ::testing::HasSubstr("'scan' is not a coefficient source (expected one of: "
                                     "material, color)"));
    EXPECT_THAT(settingsError(R"({"scattering": {"mean_free_path_mm": [1, 0, 1]}})"),
                ::testing::HasSubstr("'mean_free_path_mm' must be positive millimetres in "
                                     "every channel, not 0"));
    EXPECT_THAT(settingsError(R"({"scattering": {"mean_free_path_mm": [1, -2, 1]}})"),
                ::testing::HasSubstr("not -2"));
    EXPECT_THAT(settingsError(R"({"scattering": {"mean_free_path_mm": 3}})"),
                ::testing::HasSubstr("'mean_free_path_mm' must be 3 numbers"));
    EXPECT_THAT(settingsError(R"({"scattering": {"eta": 0.9}})"),
                ::testing::HasSubstr("'eta' = 0.9 is outside 1..3"));
    EXPECT_THAT(settingsError(R"({"scattering": {"eta": "glass"}})"),
                ::testing::HasSubstr("'eta' must be a number or null"));
    EXPECT_THAT(settingsError(R"({"scattering": {"phase_g": 1}})"),
                ::testing::HasSubstr("'phase_g' = 1 must lie strictly between -1 and 1"));
    EXPECT_THAT(settingsError(R"({"scattering": {"phase_g": -1.5}})"),
                ::testing::HasSubstr("'phase_g' = -1.5 must lie strictly between -1 and 1"));
    EXPECT_THAT(settingsError(R"({"scattering": {"single_samples": 0}})"),
                ::testing::HasSubstr("'single_samples' = 0 is outside 1..64"));
    EXPECT_THAT(settingsError(R"({"scattering": {"scale": 0}})"),
                ::testing::HasSubstr("'scale' = 0 is outside 0..1000 (exclusive of 0)"));
    // Single scattering from a Gaussian-only material's coefficients: there are none.
    EXPECT_THAT(settingsError(R"({"scattering": {"method": "single", "coefficients": "material",
                                                 "material": "skin-deon"}})"),
                ::testing::HasSubstr("the material 'skin-deon' is a Gaussian set without "
                                     "measured σs′ and σa"));
    // ... which is fine while only the Gaussian blur runs.
    const test::TempDir dir;
    const auto gaussian =
        dir.write("gaussian.json",
                  R"({"scattering": {"coefficients": "material", "material": "skin-deon"}})");
    EXPECT_EQ(readSettingsFile(gaussian).scattering.coefficients, CoefficientSource::Material);
}

TEST(RenderSettingsTest, LightMapSettingsRoundTripAndRefuseImpossibleValues) {
    RenderSettings settings;
    settings.shading.shadows = false;
    settings.shading.shadowBias = 3.5f;
    settings.shading.shadowSoftness = 0.5f;
    settings.shading.lightMapResolution = 512;
    settings.scattering.lightPath = LightPath::Screen;
    settings.scattering.transmission = false;
    settings.shading.lights.push_back({{0, 0, 1}, {1, 1, 1}, LightSpace::View});
    const RenderSettings back = nlohmann::json(settings).get<RenderSettings>();
    ASSERT_EQ(back.shading.lights.size(), 1u);
    EXPECT_EQ(back.shading.lights[0].space, LightSpace::View);
    EXPECT_FALSE(back.scattering.transmission);
    EXPECT_FALSE(back.shading.shadows);
    EXPECT_EQ(back.shading.shadowBias, 3.5f);
    EXPECT_EQ(back.shading.shadowSoftness, 0.5f);
    EXPECT_EQ(back.shading.lightMapResolution, 512);
    EXPECT_EQ(back.scattering.lightPath, LightPath::Screen);
    // Defaults: shadows on, the light maps' entries for single scattering.
    EXPECT_TRUE(RenderSettings{}.shading.shadows);
    EXPECT_EQ(RenderSettings{}.scattering.lightPath, LightPath::LightMap);

    const auto refusal = [](const nlohmann::json& json) {
        try {
            json.get<RenderSettings>();
        } catch (const Error& error) {
            return std::string(error.what());
        }
        return std::string("accepted");
    };
    EXPECT_THAT(refusal({{"shading", {{"light_map_resolution", 8}}}}),
                ::testing::HasSubstr("'light_map_resolution' must be 0 (from the point spacing) "
                                     "or 16 to 8192"));
    EXPECT_THAT(refusal({{"shading", {{"light_map_resolution", 9000}}}}),
                ::testing::HasSubstr("'light_map_resolution' = 9000 is outside 0..8192"));
    EXPECT_THAT(refusal({{"shading", {{"shadow_bias", -1}}}}),
                ::testing::HasSubstr("'shadow_bias' = -1 is outside"));
    EXPECT_THAT(refusal({{"scattering", {{"light_path", "shadow_map"}}}}),
                ::testing::HasSubstr("shadow_map"));
    EXPECT_THAT(
        refusal({{"shading", {{"lights", {{{"direction", {0, 1, 0}}, {"space", "eye"}}}}}}}),
        ::testing::HasSubstr("eye"));
}

TEST(RenderSettingsTest, ALightFixedToTheViewPointsWhereTheViewSays) {
    // A camera at +x looking at the origin: the view's +z (towards the eye) is the scene's +x,
    // its +x (right) the scene's -z.
    const glm::dmat4 view = glm::lookAt(glm::dvec3(5, 0, 0), glm::dvec3(0), glm::dvec3(0, 1, 0));
    const auto inWorld = [&](glm::vec3 direction, LightSpace space) {
        return towardsLightInWorld({direction, glm::vec3(1.0f), space}, view);
    };
    const glm::dvec3 towardsEye = inWorld({0, 0, 2}, LightSpace::View);
    EXPECT_NEAR(towardsEye.x, 1.0, 1e-12);
    EXPECT_NEAR(inWorld({1, 0, 0}, LightSpace::View).z, -1.0, 1e-12);
    EXPECT_NEAR(inWorld({0, 3, 0}, LightSpace::World).y, 1.0, 1e-12);  // normalised, as given
}

}  // namespace
}  // namespace subscan
