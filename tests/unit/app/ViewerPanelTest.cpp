#include <optional>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/viewer/ViewerPanel.h"
#include "sss/MaterialLibrary.h"

namespace subscan::viewer {
namespace {

using ::testing::HasSubstr;

ScatteringSettings singleFromMaterial(const std::string& material) {
    ScatteringSettings settings;
    settings.method = ScatteringMethod::Single;
    settings.coefficients = CoefficientSource::Material;
    settings.material = material;
    return settings;
}

TEST(ViewerPanelTest, RefusedCombinationsKeepTheLastGoodSettingsAndAreReportedOnce) {
    ASSERT_FALSE(findMaterial("skin-deon").sigmaSPrime.has_value());  // Gaussian only
    ASSERT_TRUE(findMaterial("skin1").sigmaSPrime.has_value());       // measured
    const ScatteringSettings good = singleFromMaterial("skin1");
    AppliedScattering applied(good);
    EXPECT_EQ(applied.offer(good), std::nullopt);
    EXPECT_EQ(applied.settings().material, "skin1");
    EXPECT_TRUE(applied.refusal().empty());

    // The panel picks a Gaussian-only material while single scattering takes the material's
    // coefficients: refused with the renderer's own sentence, once, not every frame.
    const ScatteringSettings bad = singleFromMaterial("skin-deon");
    const std::optional<std::string> refusal = applied.offer(bad);
    ASSERT_TRUE(refusal.has_value());
    EXPECT_THAT(*refusal, HasSubstr("'skin-deon' is a Gaussian set without measured"));
    EXPECT_EQ(applied.refusal(), *refusal);
    for (int frame = 0; frame < 3; ++frame) {
        EXPECT_EQ(applied.offer(bad), std::nullopt);
        EXPECT_EQ(applied.refusal(), *refusal);
    }
    EXPECT_EQ(applied.settings().material, "skin1");
    EXPECT_EQ(applied.settings().coefficients, CoefficientSource::Material);

    // Another refused change is reported again.
    ScatteringSettings worse = singleFromMaterial("marble-jimenez");
    const std::optional<std::string> second = applied.offer(worse);
    ASSERT_TRUE(second.has_value());
    EXPECT_THAT(*second, HasSubstr("'marble-jimenez'"));
    EXPECT_EQ(applied.settings().material, "skin1");

    // Mended by either way out the sentence names: colour coefficients or the Gaussian blur
    // alone take a Gaussian-only material.
    worse.coefficients = CoefficientSource::Color;
    EXPECT_EQ(applied.offer(worse), std::nullopt);
    EXPECT_TRUE(applied.refusal().empty());
    EXPECT_EQ(applied.settings().material, "marble-jimenez");
    EXPECT_EQ(applied.settings().coefficients, CoefficientSource::Color);
    ScatteringSettings blur = singleFromMaterial("skin-deon");
    blur.method = ScatteringMethod::Gaussian;
    EXPECT_EQ(applied.offer(blur), std::nullopt);
    EXPECT_EQ(applied.settings().material, "skin-deon");
    EXPECT_EQ(applied.settings().method, ScatteringMethod::Gaussian);
}

TEST(ViewerPanelTest, ImpossibleValuesAreRefusedToo) {
    AppliedScattering applied{ScatteringSettings{}};
    ScatteringSettings settings;
    settings.meanFreePathMm.g = 0.0f;
    EXPECT_THAT(applied.offer(settings).value_or(""), HasSubstr("mean_free_path_mm"));
    settings = {};
    settings.phaseG = 1.0f;
    EXPECT_THAT(applied.offer(settings).value_or(""), HasSubstr("phase_g"));
    settings = {};
    settings.eta = 0.5f;
    EXPECT_THAT(applied.offer(settings).value_or(""), HasSubstr("eta"));
    EXPECT_EQ(applied.settings().meanFreePathMm, kMarbleMeanFreePathMm);
    EXPECT_EQ(applied.settings().phaseG, 0.0f);
    EXPECT_FALSE(applied.settings().eta.has_value());
}

TEST(ViewerPanelTest, InitialSettingsAreCheckedByTheFirstOffer) {
    // Settings that did not pass through the CLI's check are not trusted either.
    AppliedScattering applied(singleFromMaterial("skin-jimenez"));
    EXPECT_TRUE(applied.offer(singleFromMaterial("skin-jimenez")).has_value());
}

}  // namespace
}  // namespace subscan::viewer
