// ComputeStages over a region: work groups round the region up, so every shader that takes its
// texel from dispatchTexel() must skip those past it (insideRegion). A shader that forgets is
// refused when it is built, and a region's rounded-up invocations write nothing.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "core/Error.h"
#include "gpu/GlObjects.h"
#include "gpu/ShaderSources.h"
#include "render/ComputeStages.h"
#include "shared/bindings.h"
#include "support/GlTestSupport.h"

namespace subscan {
namespace {

/// A shader directory with the shared headers and one test shader that marks its texels in an
/// r32f image, testing insideRegion() or not.
class RegionShaders {
  public:
    explicit RegionShaders(bool testsRegion)
        : directory_(std::filesystem::temp_directory_path() /
                     ("subscan-region-" + std::to_string(testsRegion) + "-" +
                      std::to_string(::getpid()))) {
        const ShaderSources embedded(std::nullopt);
        for (const char* path : {"shared/bindings.h", "shared/common.glsl", "shared/region.glsl"}) {
            write(path, embedded.raw(path));
        }
        const std::string check = testsRegion ? " || !insideRegion(texel)" : "";
        write("test/Mark.comp",
              "#version 450\n#include \"shared/common.glsl\"\n#include \"shared/region.glsl\"\n"
              "layout(local_size_x = SUBSCAN_IMAGE_GROUP_SIZE, local_size_y = "
              "SUBSCAN_IMAGE_GROUP_SIZE) in;\n"
              "layout(binding = SUBSCAN_IMAGE_OUT0, r32f) writeonly uniform image2D marks;\n"
              "void main() {\n  ivec2 texel = dispatchTexel();\n"
              "  if (any(greaterThanEqual(texel, imageSize(marks)))" +
                  check + ") {\n    return;\n  }\n  imageStore(marks, texel, vec4(1.0));\n}\n");
    }
    ~RegionShaders() { std::filesystem::remove_all(directory_); }
    ShaderSources sources() const { return ShaderSources(directory_); }

  private:
    void write(const std::string& path, const std::string& text) const {
        std::filesystem::create_directories((directory_ / path).parent_path());
        std::ofstream(directory_ / path) << text;
    }
    std::filesystem::path directory_;
};

TEST(ComputeStagesGLTest, AShaderThatIgnoresItsRegionIsRefused) {
    test::glTestContext();
    const RegionShaders shaders(false);
    try {
        ComputeStages stages(shaders.sources(), "test/Mark.comp", {"MARK"});
        FAIL() << "built a shader that writes past its region";
    } catch (const Error& error) {
        EXPECT_NE(std::string(error.what()).find("insideRegion"), std::string::npos)
            << error.what();
    }
}

TEST(ComputeStagesGLTest, ARegionsRoundedUpInvocationsWriteNothing) {
    test::glTestContext();
    const RegionShaders shaders(true);
    const ComputeStages stages(shaders.sources(), "test/Mark.comp", {"MARK"});
    constexpr int kWidth = 40;
    constexpr int kHeight = 30;
    Texture marks(TextureFormat::R32F, kWidth, kHeight, "marks");
    marks.clear();
    marks.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    // 13 x 9 texels: neither side a multiple of the work group's.
    const TexelRegion region{{5, 7}, {13, 9}};
    stages.runOverRegion(0, region);
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    const std::vector<float> values = marks.readFloats();
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            const bool inside = x >= 5 && x < 18 && y >= 7 && y < 16;
            ASSERT_EQ(values[static_cast<std::size_t>(y * kWidth + x)], inside ? 1.0f : 0.0f)
                << "texel " << x << ", " << y;
        }
    }
}

}  // namespace
}  // namespace subscan
