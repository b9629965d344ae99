// The 64-bit rasterizer's shaders cannot run on llvmpipe (no GL_NV_shader_atomic_int64), so
// the GL tests skip them there; here glslang's reference compiler checks that every variant
// compiles, wherever glslangValidator (Debian's glslang-tools) is installed.
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "gpu/ShaderSources.h"
#include "render/RasterizePointsPass.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

bool hasValidator() {
    return std::system("command -v glslangValidator >/dev/null 2>&1") == 0;
}

/// glslangValidator's exit status for `source` as a compute shader, its output in `log`.
int validate(const test::TempDir& dir, const std::string& name, std::string source,
             std::string& log) {
    // glslang does not fold uintBitsToFloat in a global const's initializer, which GLSL 4.50
    // (§4.3.3: built-in calls on constants are constant expressions) and Mesa allow: the same
    // value as a macro.
    const std::string infinity = "const float kInfinity = uintBitsToFloat(0x7F800000u);";
    if (const std::size_t at = source.find(infinity); at != std::string::npos) {
        source.replace(at, infinity.size(), "#define kInfinity uintBitsToFloat(0x7F800000u)");
    }
    const auto shader = dir.write(name + ".comp", source);
    const auto output = dir / (name + ".log");
    const int status = std::system(
        ("glslangValidator '" + shader.string() + "' >'" + output.string() + "' 2>&1").c_str());
    log = test::fileBytes(output);
    return status;
}

TEST(RasterizePointsShaderTest, Int64VariantsCompile) {
    if (!hasValidator()) {
        GTEST_SKIP() << "glslangValidator (glslang-tools, installed by scripts/setup-deps.sh) is "
                        "not on PATH";
    }
    const test::TempDir dir;
    const ShaderSources sources(std::nullopt);
    int index = 0;
    for (const std::string& defines : RasterizePointsPass::int64VariantDefines()) {
        const std::string source = sources.load(RasterizePointsPass::shaderPath(), defines);
        std::string log;
        EXPECT_EQ(validate(dir, "variant" + std::to_string(index++), source, log), 0)
            << defines << log;
    }
}

TEST(RasterizePointsShaderTest, TheValidatorRefusesInt64AtomicsWithoutTheExtension) {
    // The control: without GL_NV_shader_atomic_int64 the same source must not compile, or the
    // test above would pass whatever the shaders say.
    if (!hasValidator()) {
        GTEST_SKIP() << "glslangValidator is not on PATH";
    }
    const test::TempDir dir;
    std::string source = ShaderSources(std::nullopt)
                             .load(RasterizePointsPass::shaderPath(),
                                   RasterizePointsPass::int64VariantDefines().front());
    const std::string extension = "#extension GL_NV_shader_atomic_int64 : require\n";
    const std::size_t at = source.find(extension);
    ASSERT_NE(at, std::string::npos);
    source.erase(at, extension.size());
    std::string log;
    EXPECT_NE(validate(dir, "without", source, log), 0) << log;
}

}  // namespace
}  // namespace subscan
