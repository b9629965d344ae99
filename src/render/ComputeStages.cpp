#include "render/ComputeStages.h"

#include <algorithm>

#include <fmt/format.h>

#include "core/Error.h"

#include "shared/bindings.h"

namespace subscan {

std::vector<TexelRegion> texelsOutside(const TexelRegion& old, const TexelRegion& current) {
    const glm::ivec2 oldEnd = old.origin + old.size, end = current.origin + current.size;
    std::vector<TexelRegion> parts;
    auto add = [&](glm::ivec2 from, glm::ivec2 to) {
        if (to.x > from.x && to.y > from.y) {
            parts.push_back({from, to - from});
        }
    };
    const int top = std::min(oldEnd.y, current.origin.y);
    const int bottom = std::max(old.origin.y, end.y);
    add(old.origin, {oldEnd.x, top});
    add({old.origin.x, bottom}, oldEnd);
    const int bandTop = std::max(old.origin.y, current.origin.y);
    const int bandBottom = std::min(oldEnd.y, end.y);
    add({old.origin.x, bandTop}, {std::min(oldEnd.x, current.origin.x), bandBottom});
    add({std::max(old.origin.x, end.x), bandTop}, {oldEnd.x, bandBottom});
    return parts;
}

ComputeStages::ComputeStages(const ShaderSources& sources, std::string_view path,
                             const std::vector<std::string>& names, std::string_view defines) {
    for (const std::string& active : names) {
        std::string variant(defines);
        for (const std::string& name : names) {
            variant += fmt::format("#define STAGE_{} {}\n", name, name == active ? 1 : 0);
        }
        programs_.push_back(Program::compute(sources, path, variant));
        hasLevelUniform_.push_back(glGetProgramResourceLocation(programs_.back().id(), GL_UNIFORM,
                                                                "level") == SUBSCAN_UNIFORM_LEVEL);
        const bool origin =
            glGetProgramResourceLocation(programs_.back().id(), GL_UNIFORM, "dispatchOrigin") ==
            SUBSCAN_UNIFORM_ORIGIN;
        const bool end = glGetProgramResourceLocation(programs_.back().id(), GL_UNIFORM,
                                                      "dispatchEnd") == SUBSCAN_UNIFORM_END;
        if (origin != end) {
            throw Error(
                fmt::format("{} (STAGE_{}) takes its texel from dispatchTexel() but does "
                            "not test insideRegion()",
                            path, active));
        }
        hasRegionUniforms_.push_back(origin);
    }
}

void ComputeStages::setRegionUniforms(const Program& program, const TexelRegion& region) {
    const glm::ivec2 end = region.origin + region.size;
    glProgramUniform2i(program.id(), SUBSCAN_UNIFORM_ORIGIN, region.origin.x, region.origin.y);
    glProgramUniform2i(program.id(), SUBSCAN_UNIFORM_END, end.x, end.y);
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
    if (hasRegionUniforms_[stage]) {
        setRegionUniforms(program, region);
    }
    Program::dispatch2D(region.size.x, region.size.y, SUBSCAN_IMAGE_GROUP_SIZE,
                        SUBSCAN_IMAGE_GROUP_SIZE);
}

}  // namespace subscan
