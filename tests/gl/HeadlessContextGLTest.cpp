// Several headless contexts in one process (the Python module gives each Renderer its own):
// contexts on the same EGL display live and die independently.
#include <cstdint>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "gpu/GlContext.h"
#include "gpu/GlObjects.h"
#include "support/GlTestSupport.h"

namespace subscan {
namespace {

/// Clears a small integer texture on the current context and reads it back.
std::vector<std::uint32_t> clearedTexels(std::uint32_t value) {
    Texture texture(TextureFormat::R32UI, 3, 2, "test.texels");
    texture.clearUint(value);
    return texture.readUints();
}

TEST(HeadlessContextGLTest, DroppingOneContextLeavesTheOthersWorking) {
    GlContext& shared = test::glTestContext();  // lives through the test, as other renderers do
    auto first = createHeadlessContext({.preferHardware = true, .debugOutput = true});
    auto second = createHeadlessContext({.preferHardware = true, .debugOutput = true});
    first.reset();  // used to terminate the EGL display every context shares

    ASSERT_NO_THROW(second->makeCurrent());
    EXPECT_EQ(clearedTexels(7u), std::vector<std::uint32_t>(6, 7u));
    EXPECT_TRUE(second->takeDebugErrors().empty());
    second.reset();

    ASSERT_NO_THROW(shared.makeCurrent());
    EXPECT_EQ(clearedTexels(9u), std::vector<std::uint32_t>(6, 9u));
}

TEST(HeadlessContextGLTest, DroppingAContextKeepsAnotherCurrentOnThisThread) {
    GlContext& shared = test::glTestContext();
    auto other = createHeadlessContext({.preferHardware = true, .debugOutput = true});
    shared.makeCurrent();
    other.reset();  // only its own context is released, not the one current here
    EXPECT_EQ(clearedTexels(3u), std::vector<std::uint32_t>(6, 3u));
}

}  // namespace
}  // namespace subscan
