#pragma once

#include "gpu/GlContext.h"

namespace subscan::test {

/// One headless context per test executable, with GL debug output recorded so a GL error in a
/// pass fails the test. Created on first use; CI has Mesa's llvmpipe, so failing to create it
/// fails the test rather than skipping it.
GlContext& glTestContext();

}  // namespace subscan::test
