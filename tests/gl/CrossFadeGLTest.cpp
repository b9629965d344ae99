// The viewer's cross-fade between two sets of a streamed view's nodes: its weight over time and
// its mix, in linear light, against the CPU's sRGB transfer functions (core/Srgb.h).
#include "app/viewer/CrossFade.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>

#include "core/Srgb.h"
#include "support/GlTestSupport.h"

namespace subscan::viewer {
namespace {

// Not a multiple of the 8x8 work group: the edge groups must stop at the picture's border.
constexpr int kWidth = 13;
constexpr int kHeight = 9;

/// A picture whose every texel and channel differs, 0..1 sRGB-encoded.
std::vector<float> picture(int seed) {
    std::vector<float> values(4 * kWidth * kHeight);
    for (std::size_t i = 0; i < values.size(); ++i) {
        values[i] = i % 4 == 3 ? 1.0f : static_cast<float>((i * 37 + seed * 101) % 256) / 255.0f;
    }
    return values;
}

Texture texture(const std::vector<float>& values) {
    Texture result(TextureFormat::RGBA8, kWidth, kHeight, "test.picture");
    result.uploadFloats(values);
    return result;
}

TEST(CrossFadeGLTest, WeightEasesFromTheOldPictureToTheNew) {
    EXPECT_EQ(crossFadeWeight(-1.0), 0.0);
    EXPECT_EQ(crossFadeWeight(0.0), 0.0);
    EXPECT_DOUBLE_EQ(crossFadeWeight(kCrossFadeSeconds / 2), 0.5);
    EXPECT_EQ(crossFadeWeight(kCrossFadeSeconds), 1.0);
    EXPECT_EQ(crossFadeWeight(10.0), 1.0);
    // Flat at both ends: the first and last steps change little.
    EXPECT_LT(crossFadeWeight(kCrossFadeSeconds * 0.05), 0.01);
    EXPECT_GT(crossFadeWeight(kCrossFadeSeconds * 0.95), 0.99);
}

TEST(CrossFadeGLTest, MixesThePicturesInLinearLightAndEndsOnTime) {
    test::glTestContext();
    CrossFade fade{ShaderSources()};
    const std::vector<float> oldValues = picture(1), newValues = picture(2);
    const Texture oldPicture = texture(oldValues), newPicture = texture(newValues);
    fade.start(oldPicture);
    // Started, not yet blended: under way however long the new picture's first frame takes.
    EXPECT_TRUE(fade.active(newPicture, 1000.0));
    const Texture otherSize(TextureFormat::RGBA8, kWidth + 1, kHeight, "test.resized");
    EXPECT_FALSE(fade.active(otherSize, 0.0));  // the window changed: nothing to fade from
    // The first blend shows the old picture and starts the fade's clock.
    const double start = 100.0;
    const std::vector<std::uint8_t> first = fade.blend(newPicture, start).readRgba8();
    int notOld = 0;
    for (std::size_t i = 0; i < first.size(); ++i) {
        // One step: the sRGB round trip through linear light on the GPU.
        notOld += std::abs(first[i] - static_cast<int>(std::lround(oldValues[i] * 255.0f))) > 1;
    }
    EXPECT_EQ(notOld, 0);
    const double now = start + kCrossFadeSeconds * 0.4;
    const float weight = static_cast<float>(crossFadeWeight(now - start));
    const std::vector<std::uint8_t> blended = fade.blend(newPicture, now).readRgba8();
    ASSERT_EQ(blended.size(), oldValues.size());
    int wrong = 0, fromEither = 0;
    for (std::size_t i = 0; i < blended.size(); ++i) {
        if (i % 4 == 3) {
            continue;
        }
        // The textures hold the values rounded to 8 bits, as the GPU reads them.
        const float before = srgbToLinear(std::round(oldValues[i] * 255.0f) / 255.0f);
        const float after = srgbToLinear(std::round(newValues[i] * 255.0f) / 255.0f);
        const int expected = srgb8Channel(before + (after - before) * weight);
        // One step: the GPU's pow and rounding against the CPU's.
        wrong += std::abs(blended[i] - expected) > 1 ? 1 : 0;
        // A mix in encoded values (the mistake this guards against) lies elsewhere for most.
        const int encodedMix = static_cast<int>(
            std::lround((oldValues[i] + (newValues[i] - oldValues[i]) * weight) * 255.0f));
        fromEither += std::abs(encodedMix - expected) > 1 ? 1 : 0;
    }
    EXPECT_EQ(wrong, 0);
    EXPECT_GT(fromEither, static_cast<int>(blended.size()) / 4);
    EXPECT_FALSE(fade.active(newPicture, start + kCrossFadeSeconds * 1.01));
    fade.stop();
    EXPECT_FALSE(fade.active(newPicture, start));
}

}  // namespace
}  // namespace subscan::viewer
