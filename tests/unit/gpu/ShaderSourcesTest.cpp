#include <cstdlib>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "gpu/ShaderSources.h"
#include "support/TestSupport.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

TEST(ShaderSourcesTest, EveryEmbeddedShaderExpandsWithVersionFirst) {
    const ShaderSources sources(std::nullopt);
    for (const char* path : {"render/RasterizePoints.comp", "render/DrawPoints.vert",
                             "render/DrawPoints.frag", "render/Present.comp"}) {
        const std::string text = sources.load(path, "#define EXTRA 1\n");
        EXPECT_TRUE(text.starts_with("#version 450\n#define EXTRA 1\n")) << path;
        EXPECT_THAT(text, HasSubstr("struct FrameParams")) << path;  // from shared/bindings.h
        EXPECT_THAT(text, ::testing::Not(HasSubstr("#include \""))) << path;
    }
}

TEST(ShaderSourcesTest, OverrideDirectoryIncludesOnceAndNamesMissingFiles) {
    const test::TempDir dir;
    std::filesystem::create_directories(dir / "lib");
    dir.write("lib/a.glsl", "#include \"lib/b.glsl\"\nfloat a;\n");
    dir.write("lib/b.glsl", "#include \"lib/a.glsl\"\nfloat b;\n");  // a cycle
    dir.write("main.comp",
              "#version 450\n#include \"lib/a.glsl\"\n#include \"lib/b.glsl\"\nvoid main() {}\n");
    dir.write("broken.comp", "#version 450\n#include \"lib/none.glsl\"\n");
    const ShaderSources sources(dir.path());
    const std::string text = sources.load("main.comp");
    EXPECT_EQ(text.find("float a;"), text.rfind("float a;"));  // once
    EXPECT_EQ(text.find("float b;"), text.rfind("float b;"));
    EXPECT_LT(text.find("float b;"), text.find("float a;"));  // b is included inside a
    try {
        sources.load("broken.comp");
        FAIL() << "missing include accepted";
    } catch (const Error& error) {
        EXPECT_THAT(error.what(), HasSubstr("'lib/none.glsl' is not part of this build"));
    }
}

TEST(ShaderSourcesTest, AnOverrideThatIsNoDirectoryIsOneSentence) {
    const test::TempDir dir;
    dir.write("file.comp", "#version 450\n");
    for (const std::filesystem::path& path : {dir / "missing", dir / "file.comp"}) {
        try {
            const ShaderSources sources(path);
            FAIL() << path << " accepted";
        } catch (const Error& error) {
            EXPECT_THAT(error.what(), HasSubstr("'" + path.string() + "'"));
            EXPECT_THAT(error.what(), HasSubstr("is not a directory"));
        }
    }
    // The environment's override goes through the same check.
    const char* before = std::getenv("SUBSCAN_SHADER_DIR");
    const std::string saved = before ? before : "";
    setenv("SUBSCAN_SHADER_DIR", (dir / "missing").c_str(), 1);
    EXPECT_THROW(ShaderSources(), Error);
    setenv("SUBSCAN_SHADER_DIR", dir.path().c_str(), 1);
    EXPECT_NO_THROW(ShaderSources());
    if (before) {
        setenv("SUBSCAN_SHADER_DIR", saved.c_str(), 1);
    } else {
        unsetenv("SUBSCAN_SHADER_DIR");
    }
}

}  // namespace
}  // namespace subscan
