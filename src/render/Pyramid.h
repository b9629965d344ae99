#pragma once

#include <cstddef>

#include "shared/bindings.h"

namespace subscan {

/// Level sizes and buffer offsets of an image pyramid over a width x height image: level R is
/// ceil(W / 2^R) x ceil(H / 2^R), down to 1x1. Throws subscan::Error beyond the level limit.
gpu::PyramidLayout pyramidLayout(int width, int height);

/// Texels of all levels together (the buffer size in elements).
inline std::size_t pyramidTexels(const gpu::PyramidLayout& layout) {
    return layout.info.y;
}

}  // namespace subscan
