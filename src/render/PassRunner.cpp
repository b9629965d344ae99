#include "render/PassRunner.h"

#include <string>
#include <string_view>
#include <unordered_set>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

PassRunner::PassRunner(GlContext& context, TimingMode timing)
    : context_(context), timer_(context.capabilities(), timing) {}

std::vector<PassTiming> PassRunner::run(std::span<RenderPass* const> passes, FrameContext& frame) {
    // What this frame's passes have written so far: an image an earlier frame left behind does
    // not count (it would be read stale).
    std::unordered_set<std::string_view> written;
    for (RenderPass* pass : passes) {
        const std::string_view name = pass->name();
        for (const std::string_view input : pass->inputs(frame.settings)) {
            if (!written.contains(input)) {
                throw Error(
                    fmt::format("the pass {} needs the image '{}', which no earlier pass "
                                "writes",
                                name, input));
            }
        }
        glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, static_cast<GLsizei>(name.size()),
                         name.data());
        timer_.begin(name);
        pass->execute(frame);
        timer_.end();
        glPopDebugGroup();
        if (const std::vector<std::string> errors = context_.takeDebugErrors(); !errors.empty()) {
            timer_.collect();
            throw Error(
                fmt::format("OpenGL reported an error in the pass {}: {}", name, errors.front()));
        }
        for (const std::string_view output : pass->outputs(frame.settings)) {
            if (!frame.resources.has(output)) {
                throw Error(fmt::format("the pass {} did not write its output '{}'", name, output));
            }
            written.insert(output);
        }
    }
    return timer_.collect();
}

}  // namespace subscan
