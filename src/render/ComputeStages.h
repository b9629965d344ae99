#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>

#include "gpu/GlObjects.h"
#include "gpu/ShaderSources.h"

namespace subscan {

/// A rectangle of texels on one image or pyramid level.
struct TexelRegion {
    glm::ivec2 origin{0};
    glm::ivec2 size{0};
};

/// The texels of `old` outside `current`: up to four rectangles (above, below, left, right).
std::vector<TexelRegion> texelsOutside(const TexelRegion& old, const TexelRegion& current);

/// The variants of one compute shader, one per STAGE_* macro: `names` {"COPY", "REDUCE"} build
/// the shader once with STAGE_COPY 1 (others 0), once with STAGE_REDUCE 1, and so on, each
/// after `defines` (lines of #define that all variants share).
class ComputeStages {
  public:
    ComputeStages(const ShaderSources& sources, std::string_view path,
                  const std::vector<std::string>& names, std::string_view defines = {});
    const Program& operator[](std::size_t stage) const { return programs_[stage]; }

    /// Runs `stage` over a width x height grid of image-sized work groups, with the per-level
    /// uniform set to `level` where the stage declares it.
    void runOverImage(std::size_t stage, int width, int height, unsigned level = 0) const;
    /// The same over `region` only; the stage must take its texel from dispatchTexel() and skip
    /// those where insideRegion() is false (shared/region.glsl).
    void runOverRegion(std::size_t stage, const TexelRegion& region, unsigned level = 0) const;

    /// The uniforms of shared/region.glsl for a dispatch of `program` over `region`.
    static void setRegionUniforms(const Program& program, const TexelRegion& region);

  private:
    std::vector<Program> programs_;
    std::vector<bool> hasLevelUniform_;
    std::vector<bool> hasRegionUniforms_;
};

}  // namespace subscan
