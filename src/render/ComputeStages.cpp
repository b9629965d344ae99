#include "render/ComputeStages.h"

#include <fmt/format.h>

#include "shared/bindings.h"

namespace subscan {

ComputeStages::ComputeStages(const ShaderSources& sources, std::string_view path,
                             const std::vector<std::string>& names) {
    for (const std::string& active : names) {
        std::string defines;
        for (const std::string& name : names) {
            defines += fmt::format("#define STAGE_{} {}\n", name, name == active ? 1 : 0);
        }
        programs_.push_back(Program::compute(sources, path, defines));
        hasLevelUniform_.push_back(glGetProgramResourceLocation(programs_.back().id(), GL_UNIFORM,
                                                                "level") == SUBSCAN_UNIFORM_LEVEL);
        hasOriginUniform_.push_back(
            glGetProgramResourceLocation(programs_.back().id(), GL_UNIFORM, "dispatchOrigin") ==
            SUBSCAN_UNIFORM_ORIGIN);
    }
}

void ComputeStages::runOverImage(std::size_t stage, int width, int height, unsigned level) const {
    runOverRegion(stage, {glm::ivec2(0), glm::ivec2(width, height)}, level);
}

void ComputeStages::runOverRegion(std::size_t stage, const TexelRegion& region,
                                  unsigned level) const {
    const Program& program = programs_[stage];
    program.use();
    if (hasLevelUniform_[stage]) {
        glProgramUniform1ui(program.id(), SUBSCAN_UNIFORM_LEVEL, level);
    }
    if (hasOriginUniform_[stage]) {
        glProgramUniform2i(program.id(), SUBSCAN_UNIFORM_ORIGIN, region.origin.x, region.origin.y);
    }
    Program::dispatch2D(region.size.x, region.size.y, SUBSCAN_IMAGE_GROUP_SIZE,
                        SUBSCAN_IMAGE_GROUP_SIZE);
}

}  // namespace subscan
