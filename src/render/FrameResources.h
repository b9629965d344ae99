#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "gpu/GlObjects.h"

namespace subscan {

/// The named images passes read and write ("depth", "color", ...), allocated on first use and
/// reallocated when a pass asks for another size or format (window resize).
class FrameResources {
  public:
    /// The texture `name`, created or recreated to match; contents undefined after a change.
    Texture& ensureTexture(std::string_view name, TextureFormat format, int width, int height,
                           int levels = 1);
    /// Throws subscan::Error when no pass produced `name`.
    Texture& texture(std::string_view name);
    const Texture& texture(std::string_view name) const;
    bool has(std::string_view name) const;
    std::vector<std::string> names() const;
    /// Bytes held by all textures (mip chains included), for the memory report.
    std::size_t bytes() const;

  private:
    std::map<std::string, Texture, std::less<>> textures_;
};

}  // namespace subscan
