#pragma once

#include <map>
#include <string>
#include <string_view>

#include "gpu/GlObjects.h"

namespace subscan {

/// The named images and buffers passes read and write ("depth", "color", "pyramid", ...),
/// allocated on first use and reallocated when a pass asks for another size or format (window
/// resize). Image pyramids live in buffers: every level, any size.
class FrameResources {
  public:
    /// The texture `name`, created or recreated to match; contents undefined after a change.
    Texture& ensureTexture(std::string_view name, TextureFormat format, int width, int height);
    /// The storage buffer `name`, created or recreated when the size changes.
    Buffer& ensureBuffer(std::string_view name, std::size_t bytes);

    /// Throw subscan::Error when no pass produced `name`.
    Texture& texture(std::string_view name);
    const Texture& texture(std::string_view name) const;
    Buffer& buffer(std::string_view name);
    const Buffer& buffer(std::string_view name) const;

    /// Exchanges the textures `a` and `b` (both must exist): ping-pong images, such as the
    /// temporal filter's history, read from one while the frame writes the other.
    void swapTextures(std::string_view a, std::string_view b);

    /// A texture or buffer of that name exists.
    bool has(std::string_view name) const;
    /// Bytes held by all textures and buffers, for the memory report.
    std::size_t bytes() const;

  private:
    std::map<std::string, Texture, std::less<>> textures_;
    std::map<std::string, Buffer, std::less<>> buffers_;
};

}  // namespace subscan
