#include "support/GlTestSupport.h"

#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace subscan::test {

namespace {

/// Fails the test during which GL reported an error (debug output or glGetError), whether or not
/// the test went through PassRunner, which checks after each pass. googletest calls a listener
/// appended after its printer first at a test's end, while the test's result is still open, so
/// the failure is the test's own and printed with it.
class GlErrorListener final : public ::testing::EmptyTestEventListener {
  public:
    explicit GlErrorListener(GlContext& context) : context_(context) {}

    void OnTestEnd(const ::testing::TestInfo&) override {
        context_.makeCurrent();
        const std::vector<std::string> errors = context_.takeDebugErrors();
        for (const std::string& error : errors) {
            ADD_FAILURE() << "OpenGL reported an error during this test: " << error;
        }
    }

  private:
    GlContext& context_;
};

}  // namespace

GlContext& glTestContext() {
    static const std::unique_ptr<GlContext> context = [] {
        std::unique_ptr<GlContext> created =
            createHeadlessContext({.preferHardware = true, .debugOutput = true});
        // googletest owns and deletes the listener; the context outlives it (static).
        ::testing::UnitTest::GetInstance()->listeners().Append(new GlErrorListener(*created));
        return created;
    }();
    context->makeCurrent();
    return *context;
}

}  // namespace subscan::test
