#include "gpu/GpuClear.h"

#include <algorithm>
#include <string>

#include <glm/vector_relational.hpp>

#include "core/Error.h"
#include "shared/bindings.h"

namespace subscan {

namespace {

/// What follows a compute clear may read the cleared object any way: as an image, a storage
/// buffer, a sampled texture or buffer texture, a framebuffer, or by a read-back.
constexpr GLbitfield kAfterClear = GL_ALL_BARRIER_BITS;

/// Enough work groups to keep any GPU busy; the shader loops over the rest of the buffer (a
/// dispatch of one group per 256 words would pass the 65535 groups GL guarantees at 4K).
constexpr std::uint64_t kBufferClearGroups = 4096;

const char* imageFormatQualifier(TextureFormat format) {
    switch (format) {
        case TextureFormat::R32F:
            return "r32f";
        case TextureFormat::RG32F:
            return "rg32f";
        case TextureFormat::RGBA16F:
            return "rgba16f";
        case TextureFormat::RGBA32F:
            return "rgba32f";
        case TextureFormat::RGBA8:
            return "rgba8";
        case TextureFormat::R8:
            return "r8";
        case TextureFormat::R32UI:
            return "r32ui";
        case TextureFormat::Depth32F:
            break;
    }
    return nullptr;
}

}  // namespace

GpuClear::GpuClear(ShaderSources sources, const GlCapabilities& capabilities)
    : sources_(std::move(sources)), software_(capabilities.software) {}

bool GpuClear::byCompute(ClearPath path) const {
    return path == ClearPath::Compute || (path == ClearPath::Auto && !software_);
}

const Program& GpuClear::program(TextureFormat format) {
    auto found = imagePrograms_.find(format);
    if (found == imagePrograms_.end()) {
        const bool isUint = format == TextureFormat::R32UI;
        const std::string defines = std::string("#define CLEAR_BUFFER 0\n#define CLEAR_UINT ") +
                                    (isUint ? "1" : "0") + "\n#define IMAGE_FORMAT " +
                                    imageFormatQualifier(format) + "\n";
        found =
            imagePrograms_.emplace(format, Program::compute(sources_, "gpu/GpuClear.comp", defines))
                .first;
    }
    return found->second;
}

const Program& GpuClear::bufferProgram() {
    if (!bufferProgram_.id()) {
        bufferProgram_ = Program::compute(sources_, "gpu/GpuClear.comp",
                                          "#define CLEAR_BUFFER 1\n#define CLEAR_UINT 0\n");
    }
    return bufferProgram_;
}

void GpuClear::texture(Texture& texture, const glm::vec4& value, ClearPath path) {
    textureRegion(texture, glm::ivec2(0), glm::ivec2(texture.width(), texture.height()), value,
                  path);
}

void GpuClear::textureRegion(Texture& texture, glm::ivec2 origin, glm::ivec2 size,
                             const glm::vec4& value, ClearPath path) {
    if (size.x <= 0 || size.y <= 0) {
        return;
    }
    if (texture.format() == TextureFormat::R32UI ||
        glm::any(glm::lessThan(origin, glm::ivec2(0))) || origin.x + size.x > texture.width() ||
        origin.y + size.y > texture.height()) {
        throw Error("GpuClear::textureRegion needs a float texture and a region inside it");
    }
    if (!byCompute(path) || !imageFormatQualifier(texture.format())) {
        texture.clearRegion(origin, size, value);
        return;
    }
    program(texture.format()).use();
    glUniform4fv(0, 1, &value.x);
    store(texture, origin, size);
}

void GpuClear::textureUint(Texture& texture, std::uint32_t value, ClearPath path) {
    if (!byCompute(path)) {
        texture.clearUint(value);
        return;
    }
    if (texture.format() != TextureFormat::R32UI) {
        throw Error("GpuClear::textureUint needs an R32UI texture");
    }
    program(TextureFormat::R32UI).use();
    const glm::uvec4 values(value);
    glUniform4uiv(0, 1, &values.x);
    store(texture, glm::ivec2(0), glm::ivec2(texture.width(), texture.height()));
}

void GpuClear::store(Texture& texture, glm::ivec2 origin, glm::ivec2 size) {
    glUniform2i(1, origin.x, origin.y);
    glUniform2i(2, size.x, size.y);
    texture.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    Program::dispatch2D(size.x, size.y, SUBSCAN_IMAGE_GROUP_SIZE, SUBSCAN_IMAGE_GROUP_SIZE);
    glMemoryBarrier(kAfterClear);
}

void GpuClear::buffer(Buffer& buffer, std::uint32_t value, ClearPath path) {
    if (!byCompute(path) || buffer.borrowed()) {
        buffer.fill(value);  // refuses a borrowed buffer with its own error
        return;
    }
    const std::uint64_t words = buffer.size() / sizeof(std::uint32_t);
    if (words == 0) {
        return;
    }
    const Program& clear = bufferProgram();
    clear.use();
    glUniform1ui(0, value);
    glUniform1ui(1, static_cast<GLuint>(words));
    buffer.bindStorage(SUBSCAN_SSBO_CLEAR);
    const std::uint64_t groups = std::min<std::uint64_t>(
        kBufferClearGroups, (words + SUBSCAN_CLEAR_GROUP_SIZE - 1) / SUBSCAN_CLEAR_GROUP_SIZE);
    glDispatchCompute(static_cast<GLuint>(groups), 1, 1);
    glMemoryBarrier(kAfterClear);
}

}  // namespace subscan
