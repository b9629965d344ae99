#include "render/RenderPass.h"

#include <algorithm>

namespace subscan {

namespace {

/// Texels around the points' bounds on every level: pull reads children up to 2 texels
/// beyond a texel's own footprint, so a level's non-zero weights reach at most 2 texels past
/// the bounds scaled to it; push and normals read 1 texel around what they serve.
constexpr int kRegionMargin = 2;

}  // namespace

TexelRegion FrameContext::region(unsigned level) const {
    const glm::ivec2 size(static_cast<int>(pyramid.levels[level].y),
                          static_cast<int>(pyramid.levels[level].z));
    if (!pointBounds) {
        return {glm::ivec2(0), size};
    }
    const glm::ivec4& bounds = *pointBounds;
    if (bounds.z <= bounds.x || bounds.w <= bounds.y) {
        return {glm::ivec2(0), glm::ivec2(0)};
    }
    const glm::ivec2 first =
        glm::max(glm::ivec2(bounds.x, bounds.y) / (1 << level) - kRegionMargin, glm::ivec2(0));
    const glm::ivec2 last =
        glm::min((glm::ivec2(bounds.z, bounds.w) - 1) / (1 << level) + kRegionMargin, size - 1);
    return {first, last - first + 1};
}

Texture& FrameContext::imageOverRegion(std::string_view name, TextureFormat format,
                                       const glm::vec4& outside) const {
    Texture& image = resources.ensureTexture(name, format, width(), height());
    if (restricted()) {
        clear(image, outside);
    }
    return image;
}

Texture& FrameContext::imageOverRegion(std::string_view name, TextureFormat format, int ring,
                                       const glm::vec4& outside) const {
    Texture& image = resources.ensureTexture(name, format, width(), height());
    if (restricted()) {
        const TexelRegion inner = region(0);
        const glm::ivec2 from = glm::max(inner.origin - ring, glm::ivec2(0));
        const glm::ivec2 to =
            glm::min(inner.origin + inner.size + ring, glm::ivec2(width(), height()));
        for (const TexelRegion& part : texelsOutside({from, to - from}, inner)) {
            clear(image, part, outside);
        }
    }
    return image;
}

TexelRegion FrameContext::cloudRegion() const {
    if (!cloudPixels) {
        return {glm::ivec2(0), glm::ivec2(width(), height())};
    }
    const glm::ivec4& pixels = *cloudPixels;
    return {glm::ivec2(pixels.x, pixels.y),
            glm::max(glm::ivec2(pixels.z - pixels.x, pixels.w - pixels.y), glm::ivec2(0))};
}

bool surfaceBoundsAllowed(const RenderSettings& settings) {
    return settings.surface.restrictToPoints && settings.surface.fillDirections >= 6 &&
           isFinalImage(settings.raster.stage);
}

}  // namespace subscan
