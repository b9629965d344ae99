#include "render/FrameResources.h"

#include <utility>

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
                                       int height) {
    auto found = textures_.find(name);
    if (found == textures_.end()) {
        return textures_.emplace(std::string(name), Texture(format, width, height, name))
            .first->second;
    }
    Texture& texture = found->second;
    if (texture.format() != format || texture.width() != width || texture.height() != height) {
        texture = Texture(format, width, height, name);
    }
    return texture;
}

Buffer& FrameResources::ensureBuffer(std::string_view name, std::size_t bytes) {
    auto found = buffers_.find(name);
    if (found == buffers_.end()) {
        return buffers_.emplace(std::string(name), Buffer(bytes, nullptr, name)).first->second;
    }
    if (found->second.size() != bytes) {
        found->second = Buffer(bytes, nullptr, name);
    }
    return found->second;
}

void FrameResources::swapTextures(std::string_view a, std::string_view b) {
    std::swap(texture(a), texture(b));
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

Buffer& FrameResources::buffer(std::string_view name) {
    return const_cast<Buffer&>(std::as_const(*this).buffer(name));
}

const Buffer& FrameResources::buffer(std::string_view name) const {
    const auto found = buffers_.find(name);
    if (found == buffers_.end()) {
        throw Error(fmt::format("no render pass produced the buffer '{}'", name));
    }
    return found->second;
}

bool FrameResources::has(std::string_view name) const {
    return textures_.contains(name) || buffers_.contains(name);
}

std::size_t FrameResources::bytes() const {
    std::size_t total = 0;
    for (const auto& [name, texture] : textures_) {
        total += static_cast<std::size_t>(texture.width()) *
                 static_cast<std::size_t>(texture.height()) * bytesPerTexel(texture.format());
    }
    for (const auto& [name, buffer] : buffers_) {
        total += buffer.size();
    }
    return total;
}

}  // namespace subscan
