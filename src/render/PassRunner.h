#pragma once

#include <span>
#include <vector>

#include "gpu/GlContext.h"
#include "gpu/PassTimer.h"
#include "render/RenderPass.h"

namespace subscan {

/// Runs passes in order, each inside a GL debug group and a timer. Before a pass runs, an
/// earlier pass of the same run must have declared each of its inputs as an output; afterwards
/// its outputs must exist. When the context records debug output, a GL error inside a pass
/// becomes a subscan::Error naming that pass.
class PassRunner {
  public:
    PassRunner(GlContext& context, TimingMode timing);
    std::vector<PassTiming> run(std::span<RenderPass* const> passes, FrameContext& frame);

  private:
    GlContext& context_;
    PassTimer timer_;
};

}  // namespace subscan
