#include "render/Pyramid.h"

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

gpu::PyramidLayout pyramidLayout(int width, int height) {
    gpu::PyramidLayout layout{};
    std::uint32_t w = static_cast<std::uint32_t>(width);
    std::uint32_t h = static_cast<std::uint32_t>(height);
    std::uint32_t offset = 0;
    std::uint32_t level = 0;
    while (true) {
        if (level == SUBSCAN_MAX_PYRAMID_LEVELS) {
            throw Error(fmt::format("an image of {}x{} needs more than {} pyramid levels", width,
                                    height, SUBSCAN_MAX_PYRAMID_LEVELS));
        }
        layout.levels[level] = {offset, w, h, 0};
        offset += w * h;
        ++level;
        if (w == 1 && h == 1) {
            break;
        }
        w = (w + 1) / 2;
        h = (h + 1) / 2;
    }
    layout.info = {level, offset, 0, 0};
    return layout;
}

}  // namespace subscan
