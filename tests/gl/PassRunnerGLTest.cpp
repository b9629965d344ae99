// PassRunner checks the wiring the passes declare and turns a GL error inside a pass into an
// error naming that pass; passes here are small fakes that do (or fail to do) one thing.
#include <array>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <epoxy/gl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/Error.h"
#include "render/PassRunner.h"
#include "support/GlTestSupport.h"
#include "support/PassHarness.h"

namespace subscan {
namespace {

using ::testing::HasSubstr;

/// A pass that reads `input` (if any), writes `output` (if any, and only when `writes`), and
/// raises a GL error when asked.
class FakePass final : public RenderPass {
  public:
    FakePass(std::string name, std::string input, std::string output, bool writes = true,
             bool raisesGlError = false)
        : name_(std::move(name)),
          input_(std::move(input)),
          output_(std::move(output)),
          writes_(writes),
          raisesGlError_(raisesGlError) {}

    std::string_view name() const override { return name_; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override {
        return listOf(input_);
    }
    std::vector<std::string_view> outputs(const RenderSettings&) const override {
        return listOf(output_);
    }
    void execute(FrameContext& frame) override {
        if (writes_ && !output_.empty()) {
            frame.resources.ensureTexture(output_, TextureFormat::R32F, frame.width(),
                                          frame.height());
        }
        if (raisesGlError_) {
            GLint units = 0;
            glGetIntegerv(GL_MAX_IMAGE_UNITS, &units);
            // An image unit beyond the limit: GL_INVALID_VALUE.
            glBindImageTexture(static_cast<GLuint>(units), 0, 0, GL_FALSE, 0, GL_READ_ONLY,
                               GL_R32F);
        }
    }

  private:
    static std::vector<std::string_view> listOf(const std::string& name) {
        return name.empty() ? std::vector<std::string_view>{} : std::vector<std::string_view>{name};
    }

    std::string name_, input_, output_;
    bool writes_, raisesGlError_;
};

/// The message of the subscan::Error that `runner` throws running `passes` on `frame`.
std::string runError(PassRunner& runner, FrameContext& frame, std::vector<RenderPass*> passes) {
    try {
        runner.run(passes, frame);
    } catch (const Error& error) {
        return error.what();
    }
    ADD_FAILURE() << "the runner accepted the passes";
    return {};
}

/// The same on a new frame.
std::string runError(std::vector<RenderPass*> passes) {
    test::PassHarness harness(8, 6, RenderSettings{}, 0.1);
    FrameContext frame = harness.context();
    PassRunner runner(test::glTestContext(), TimingMode::FinishAndClock);
    return runError(runner, frame, std::move(passes));
}

TEST(PassRunnerGLTest, RunsWiredPassesInOrderAndTimesEach) {
    test::PassHarness harness(8, 6, RenderSettings{}, 0.1);
    FrameContext frame = harness.context();
    FakePass first("First", "", "a");
    FakePass second("Second", "a", "b");
    PassRunner runner(test::glTestContext(), TimingMode::FinishAndClock);
    const std::array<RenderPass*, 2> passes{&first, &second};
    const std::vector<PassTiming> timings = runner.run(passes, frame);
    ASSERT_EQ(timings.size(), 2u);
    EXPECT_EQ(timings[0].pass, "First");
    EXPECT_EQ(timings[1].pass, "Second");
    for (const PassTiming& timing : timings) {
        EXPECT_GE(timing.milliseconds, 0.0);
    }
    EXPECT_TRUE(frame.resources.has("b"));
}

TEST(PassRunnerGLTest, AnInputNoEarlierPassWritesIsNamed) {
    FakePass reader("Reader", "missing", "b");
    FakePass writer("Writer", "", "missing");
    // The writer comes after the reader: order matters.
    const std::string message = runError({&reader, &writer});
    EXPECT_THAT(message, HasSubstr("the pass Reader needs the image 'missing'"));
}

TEST(PassRunnerGLTest, AnImageAnEarlierFrameLeftIsNoInput) {
    test::PassHarness harness(8, 6, RenderSettings{}, 0.1);
    FrameContext frame = harness.context();
    FakePass writer("Writer", "", "kept");
    FakePass reader("Reader", "kept", "b");
    PassRunner runner(test::glTestContext(), TimingMode::FinishAndClock);
    runner.run(std::array<RenderPass*, 2>{&writer, &reader}, frame);
    ASSERT_TRUE(frame.resources.has("kept"));
    // The next frame leaves the writer out: the reader would read the last frame's image.
    EXPECT_THAT(runError(runner, frame, {&reader}),
                HasSubstr("the pass Reader needs the image 'kept'"));
}

TEST(PassRunnerGLTest, AnOutputThePassDidNotWriteIsNamed) {
    FakePass lazy("Lazy", "", "promised", false);
    EXPECT_THAT(runError({&lazy}), HasSubstr("the pass Lazy did not write its output 'promised'"));
}

TEST(PassRunnerGLTest, AGlErrorInAPassFailsTheFrameNamingThePass) {
    FakePass fine("Fine", "", "a");
    FakePass broken("Broken", "a", "b", true, true);
    const std::string message = runError({&fine, &broken});
    EXPECT_THAT(message, HasSubstr("OpenGL reported an error in the pass Broken"));
    EXPECT_THAT(message, ::testing::Not(HasSubstr("Fine")));
}

}  // namespace
}  // namespace subscan
