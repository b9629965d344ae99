#include "render/FrameResources.h"

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

std::size_t bytesPerTexel(TextureFormat format) {
    switch (format) {
        case TextureFormat::R8:
            return 1;
        case TextureFormat::R32F:
        case TextureFormat::R32UI:
        case TextureFormat::RGBA8:
        case TextureFormat::Depth32F:
            return 4;
        case TextureFormat::RG32F:
        case TextureFormat::RGBA16F:
            return 8;
        case TextureFormat::RGBA32F:
            return 16;
    }
    return 4;
}

}  // namespace

Texture& FrameResources::ensureTexture(std::string_view name, TextureFormat format, int width,
                                       int height, int levels) {
    auto found = textures_.find(name);
    if (found != textures_.end()) {
        Texture& texture = found->second;
        if (texture.format() == format && texture.width() == width && texture.height() == height &&
            texture.levels() == levels) {
            return texture;
        }
        texture = Texture(format, width, height, levels, name);
        return texture;
    }
    return textures_.emplace(std::string(name), Texture(format, width, height, levels, name))
        .first->second;
}

Texture& FrameResources::texture(std::string_view name) {
    return const_cast<Texture&>(std::as_const(*this).texture(name));
}

const Texture& FrameResources::texture(std::string_view name) const {
    const auto found = textures_.find(name);
    if (found == textures_.end()) {
        throw Error(fmt::format("no render pass produced the image '{}'", name));
    }
    return found->second;
}

bool FrameResources::has(std::string_view name) const {
    return textures_.contains(name);
}

std::vector<std::string> FrameResources::names() const {
    std::vector<std::string> names;
    for (const auto& [name, texture] : textures_) {
        names.push_back(name);
    }
    return names;
}

std::size_t FrameResources::bytes() const {
    std::size_t total = 0;
    for (const auto& [name, texture] : textures_) {
        for (int level = 0; level < texture.levels(); ++level) {
            total += static_cast<std::size_t>(texture.width(level)) *
                     static_cast<std::size_t>(texture.height(level)) *
                     bytesPerTexel(texture.format());
        }
    }
    return total;
}

}  // namespace subscan
