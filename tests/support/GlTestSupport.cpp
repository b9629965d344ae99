#include "support/GlTestSupport.h"

#include <memory>

namespace subscan::test {

GlContext& glTestContext() {
    static const std::unique_ptr<GlContext> context =
        createHeadlessContext({.preferHardware = true, .debugOutput = true});
    context->makeCurrent();
    return *context;
}

}  // namespace subscan::test
