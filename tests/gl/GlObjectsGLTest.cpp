// The GL object wrappers' less common views: buffers read as buffer textures, float textures
// bound as their bits, integer textures cleared. (What the passes read through these views is
// checked against CPU twins in SurfacePassesGLTest and RasterizePointsGLTest.)
#include <cstdint>
#include <numeric>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "gpu/GlObjects.h"
#include "support/GlTestSupport.h"

namespace subscan {
namespace {

std::string errorOf(auto&& call) {
    try {
        call();
    } catch (const Error& error) {
        return error.what();
    }
    return "";
}

TEST(GlObjectsGLTest, BufferTexelsNeedThirtyTwoBitChannelsOrHalvesAndNameTheBuffer) {
    test::glTestContext();
    Buffer buffer(64, nullptr, "test.pyramid");
    EXPECT_NO_THROW(buffer.bindTexels(0, TextureFormat::R32F));
    EXPECT_NO_THROW(buffer.bindTexels(0, TextureFormat::RGBA32F));  // a new view of the same
    EXPECT_NO_THROW(buffer.bindTexels(0, TextureFormat::RG32F));
    EXPECT_NO_THROW(buffer.bindTexels(0, TextureFormat::R32UI));
    EXPECT_NO_THROW(buffer.bindTexels(0, TextureFormat::RGBA16F));
    const std::string message = errorOf([&] { buffer.bindTexels(0, TextureFormat::RGBA8); });
    EXPECT_NE(message.find("'test.pyramid'"), std::string::npos) << message;
}

TEST(GlObjectsGLTest, ABorrowedBufferReadsTheCallersMemoryInPlace) {
    GlContext& context = test::glTestContext();
    std::vector<float> memory(1003);
    std::iota(memory.begin(), memory.end(), 0.5f);
    const std::span<const float> values(memory.data() + 3, 1000);  // not page aligned
    Buffer borrowed = Buffer::borrowing(values.data(), values.size_bytes(), "test.borrowed");
    // llvmpipe pins any address; elsewhere a refusal leaves no GL error behind (the test
    // context's listener fails the test on one) and the caller copies.
    if (context.capabilities().renderer.find("llvmpipe") == std::string::npos && !borrowed) {
        EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
        GTEST_SKIP() << context.capabilities().renderer << " reads no unaligned client memory";
    }
    ASSERT_TRUE(borrowed);
    EXPECT_TRUE(borrowed.borrowed());
    EXPECT_EQ(borrowed.size(), values.size_bytes());
    EXPECT_EQ(borrowed.read<float>(), std::vector<float>(values.begin(), values.end()));
    memory[3 + 500] = -7.0f;  // seen by the GPU without an upload: no copy was made
    EXPECT_EQ(borrowed.read<float>()[500], -7.0f);
    EXPECT_NO_THROW(borrowed.bindTexels(0, TextureFormat::RGBA32F));
    // The caller's memory is only read.
    const float value = 1.0f;
    const std::string message = errorOf([&] { borrowed.upload(0, sizeof(value), &value); });
    EXPECT_NE(message.find("'test.borrowed'"), std::string::npos) << message;
    EXPECT_THROW(borrowed.fill(0), Error);
    EXPECT_EQ(memory[3], 3.5f);
    EXPECT_FALSE(Buffer(16, nullptr, "test.owned").borrowed());
}

TEST(GlObjectsGLTest, ClearUintFillsAnR32uiTextureAndRefusesOthers) {
    test::glTestContext();
    Texture winners(TextureFormat::R32UI, 5, 3, "test.winners");
    winners.clearUint(0xFFFFFFFFu);
    EXPECT_EQ(winners.readUints(), std::vector<std::uint32_t>(15, 0xFFFFFFFFu));
    winners.clearUint(7u);
    EXPECT_EQ(winners.readUints(), std::vector<std::uint32_t>(15, 7u));
    Texture depth(TextureFormat::R32F, 5, 3, "test.depth");
    EXPECT_FALSE(errorOf([&] { depth.clearUint(1u); }).empty());
}

TEST(GlObjectsGLTest, OnlySingleChannelThirtyTwoBitTexturesBindAsBits) {
    test::glTestContext();
    Texture depth(TextureFormat::R32F, 4, 4, "test.depth");
    EXPECT_NO_THROW(depth.bindImageBits(0, GL_READ_WRITE));
    Texture color(TextureFormat::RGBA16F, 4, 4, "test.color");
    EXPECT_FALSE(errorOf([&] { color.bindImageBits(0, GL_READ_WRITE); }).empty());
}

}  // namespace
}  // namespace subscan
