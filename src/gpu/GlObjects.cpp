#include "gpu/GlObjects.h"

#include <algorithm>
#include <string>

#include <fmt/format.h>

#include "core/Error.h"
#include "gpu/ShaderSources.h"

namespace subscan {

namespace {

void label(GLenum identifier, GLuint id, std::string_view text) {
    if (!text.empty()) {
        glObjectLabel(identifier, id, static_cast<GLsizei>(text.size()), text.data());
    }
}

/// glGetError after an allocation: out-of-memory becomes a sentence the user can act on.
void checkAllocation(std::string_view what, std::string_view label) {
    GLenum error = glGetError();
    GLenum first = error;
    while (error != GL_NO_ERROR) {
        error = glGetError();
    }
    if (first == GL_OUT_OF_MEMORY) {
        throw Error(fmt::format("the GPU has no memory left for {} ({})", what, label));
    }
    if (first != GL_NO_ERROR) {
        throw Error(fmt::format("the GPU refused to allocate {} ({}; GL error 0x{:04x})", what,
                                label, first));
    }
}

struct FormatInfo {
    GLenum internalFormat;
    GLenum pixelFormat;
    int channels;
    bool integer;
};

FormatInfo info(TextureFormat format) {
    switch (format) {
        case TextureFormat::R32F:
            return {GL_R32F, GL_RED, 1, false};
        case TextureFormat::RG32F:
            return {GL_RG32F, GL_RG, 2, false};
        case TextureFormat::RGBA16F:
            return {GL_RGBA16F, GL_RGBA, 4, false};
        case TextureFormat::RGBA32F:
            return {GL_RGBA32F, GL_RGBA, 4, false};
        case TextureFormat::RGBA8:
            return {GL_RGBA8, GL_RGBA, 4, false};
        case TextureFormat::R32UI:
            return {GL_R32UI, GL_RED_INTEGER, 1, true};
        case TextureFormat::R8:
            return {GL_R8, GL_RED, 1, false};
        case TextureFormat::Depth32F:
            return {GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, 1, false};
    }
    return {GL_RGBA8, GL_RGBA, 4, false};
}

GLuint compileShader(GLenum stage, const std::string& source, std::string_view path) {
    const GLuint shader = glCreateShader(stage);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint compiled = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &compiled);
    if (compiled != GL_TRUE) {
        GLint length = 0;
        glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
        std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
        glGetShaderInfoLog(shader, length, nullptr, log.data());
        glDeleteShader(shader);
        std::replace(log.begin(), log.end(), '\n', ' ');
        throw Error(fmt::format("the shader '{}' does not compile: {}", path, log.c_str()));
    }
    return shader;
}

GLuint linkProgram(std::span<const GLuint> shaders, std::string_view name) {
    const GLuint program = glCreateProgram();
    for (GLuint shader : shaders) {
        glAttachShader(program, shader);
    }
    glLinkProgram(program);
    for (GLuint shader : shaders) {
        glDetachShader(program, shader);
        glDeleteShader(shader);
    }
    GLint linked = GL_FALSE;
    glGetProgramiv(program, GL_LINK_STATUS, &linked);
    if (linked != GL_TRUE) {
        GLint length = 0;
        glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
        std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
        glGetProgramInfoLog(program, length, nullptr, log.data());
        glDeleteProgram(program);
        std::replace(log.begin(), log.end(), '\n', ' ');
        throw Error(fmt::format("the shader program '{}' does not link: {}", name, log.c_str()));
    }
    label(GL_PROGRAM, program, name);
    return program;
}

}  // namespace

// ---- Buffer -------------------------------------------------------------------------------

Buffer::Buffer(std::size_t bytes, const void* data, std::string_view labelText)
    : size_(bytes), label_(labelText) {
    GLuint id = 0;
    glCreateBuffers(1, &id);
    name_ = GlName<BufferTraits>(id);
    glNamedBufferStorage(id, static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 4)), data,
                         GL_DYNAMIC_STORAGE_BIT);
    checkAllocation(fmt::format("a {:.1f} MB buffer", static_cast<double>(bytes) / 1e6), labelText);
    label(GL_BUFFER, id, labelText);
}

Buffer Buffer::borrowing(const void* data, std::size_t bytes, std::string_view labelText) {
    Buffer buffer;
    if (bytes == 0 || !epoxy_has_gl_extension("GL_AMD_pinned_memory")) {
        return buffer;
    }
    while (glGetError() != GL_NO_ERROR) {
    }
    GLuint id = 0;
    glCreateBuffers(1, &id);
    buffer.name_ = GlName<BufferTraits>(id);
    // A refusal is an answer here, not a failure: kept out of the debug output (the group's
    // pop restores its filter) and taken from glGetError.
    glPushDebugGroup(GL_DEBUG_SOURCE_APPLICATION, 0, -1, "borrowing client memory");
    glDebugMessageControl(GL_DEBUG_SOURCE_API, GL_DEBUG_TYPE_ERROR, GL_DONT_CARE, 0, nullptr,
                          GL_FALSE);
    // The extension names a bind target only (no direct-state-access entry point).
    glBindBuffer(GL_EXTERNAL_VIRTUAL_MEMORY_BUFFER_AMD, id);
    glBufferData(GL_EXTERNAL_VIRTUAL_MEMORY_BUFFER_AMD, static_cast<GLsizeiptr>(bytes), data,
                 GL_STATIC_DRAW);
    const bool refused = glGetError() != GL_NO_ERROR;
    glBindBuffer(GL_EXTERNAL_VIRTUAL_MEMORY_BUFFER_AMD, 0);
    glPopDebugGroup();
    if (refused) {
        return Buffer();
    }
    buffer.size_ = bytes;
    buffer.borrowed_ = true;
    buffer.label_ = labelText;
    label(GL_BUFFER, id, labelText);
    return buffer;
}

void Buffer::refuseWritesIfBorrowed() const {
    if (borrowed_) {
        throw Error(
            fmt::format("the buffer '{}' is the caller's memory and is not written", label_));
    }
}

void Buffer::upload(std::size_t offset, std::size_t bytes, const void* data) {
    refuseWritesIfBorrowed();
    glNamedBufferSubData(id(), static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
}

void Buffer::download(std::size_t offset, std::size_t bytes, void* data) const {
    glGetNamedBufferSubData(id(), static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes),
                            data);
}

void Buffer::fill(std::uint32_t value) {
    refuseWritesIfBorrowed();
    glClearNamedBufferData(id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &value);
}

void Buffer::bindStorage(GLuint binding) const {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, id());
}

void Buffer::bindUniform(GLuint binding) const {
    glBindBufferBase(GL_UNIFORM_BUFFER, binding, id());
}

void Buffer::bindTexels(GLuint unit, TextureFormat format) const {
    if (!texelView_ || texelFormat_ != format) {
        const bool halves = format == TextureFormat::RGBA16F;
        if (format != TextureFormat::R32F && format != TextureFormat::RG32F &&
            format != TextureFormat::RGBA32F && format != TextureFormat::R32UI && !halves) {
            throw Error(
                fmt::format("the buffer '{}' cannot be read as texels of that format: "
                            "only 32-bit channels and RGBA16F are supported",
                            label_));
        }
        const FormatInfo texel = info(format);
        const std::size_t texelBytes = static_cast<std::size_t>(texel.channels) * (halves ? 2 : 4);
        GLint maxTexels = 0;
        glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &maxTexels);
        if (size_ / texelBytes > static_cast<std::size_t>(maxTexels)) {
            throw Error(
                fmt::format("the buffer '{}' holds {} texels, more than the {} the GPU "
                            "reads through one buffer texture (use a smaller image)",
                            label_, size_ / texelBytes, maxTexels));
        }
        GLuint view = 0;
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &view);
        texelView_ = GlName<TextureTraits>(view);
        glTextureBuffer(view, texel.internalFormat, id());
        texelFormat_ = format;
    }
    glBindTextureUnit(unit, texelView_.id());
}

// ---- Texture ------------------------------------------------------------------------------

Texture::Texture(TextureFormat format, int width, int height, std::string_view labelText)
    : format_(format), width_(width), height_(height) {
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &id);
    name_ = GlName<TextureTraits>(id);
    glTextureStorage2D(id, 1, info(format).internalFormat, width, height);
    checkAllocation(fmt::format("a {}x{} texture", width, height), labelText);
    // Passes read texels explicitly (texelFetch/imageLoad); nearest keeps samplers honest too.
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    label(GL_TEXTURE, id, labelText);
}

int Texture::channels() const {
    return info(format_).channels;
}

void Texture::bindImage(GLuint unit, GLenum access) const {
    glBindImageTexture(unit, id(), 0, GL_FALSE, 0, access, info(format_).internalFormat);
}

void Texture::bindImageBits(GLuint unit, GLenum access) const {
    if (format_ != TextureFormat::R32F && format_ != TextureFormat::R32UI) {
        throw Error("only 32-bit single-channel textures can be bound as their bits");
    }
    glBindImageTexture(unit, id(), 0, GL_FALSE, 0, access, GL_R32UI);
}

void Texture::bindSampler(GLuint unit) const {
    glBindTextureUnit(unit, id());
}

void Texture::clear(const glm::vec4& value) {
    glClearTexImage(id(), 0, info(format_).pixelFormat, GL_FLOAT, &value.x);
}

void Texture::clearRegion(glm::ivec2 origin, glm::ivec2 size, const glm::vec4& value) {
    glClearTexSubImage(id(), 0, origin.x, origin.y, 0, size.x, size.y, 1, info(format_).pixelFormat,
                       GL_FLOAT, &value.x);
}

void Texture::clearUint(std::uint32_t value) {
    if (format_ != TextureFormat::R32UI) {
        throw Error("clearUint needs an R32UI texture");
    }
    glClearTexImage(id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &value);
}

namespace {

template <class T>
std::vector<T> readTexels(GLuint id, GLenum format, GLenum type, std::size_t count) {
    std::vector<T> values(count);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(id, 0, format, type, static_cast<GLsizei>(values.size() * sizeof(T)),
                      values.data());
    return values;
}

}  // namespace

std::vector<float> Texture::readFloats() const {
    return readTexels<float>(id(), info(format_).pixelFormat, GL_FLOAT,
                             static_cast<std::size_t>(width_ * height_ * channels()));
}

std::vector<std::uint32_t> Texture::readUints() const {
    return readTexels<std::uint32_t>(id(), info(format_).pixelFormat, GL_UNSIGNED_INT,
                                     static_cast<std::size_t>(width_ * height_ * channels()));
}

std::vector<std::uint8_t> Texture::readRgba8() const {
    return readTexels<std::uint8_t>(id(), GL_RGBA, GL_UNSIGNED_BYTE,
                                    static_cast<std::size_t>(width_ * height_ * 4));
}

void Texture::uploadFloats(std::span<const float> values) {
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(id(), 0, 0, 0, width_, height_, info(format_).pixelFormat, GL_FLOAT,
                        values.data());
}

// ---- Program ------------------------------------------------------------------------------

Program Program::compute(const ShaderSources& sources, std::string_view path,
                         std::string_view defines) {
    const GLuint shader = compileShader(GL_COMPUTE_SHADER, sources.load(path, defines), path);
    return Program(linkProgram(std::span(&shader, 1), path));
}

Program Program::graphics(const ShaderSources& sources, std::string_view vertexPath,
                          std::string_view fragmentPath, std::string_view defines) {
    const GLuint vertex =
        compileShader(GL_VERTEX_SHADER, sources.load(vertexPath, defines), vertexPath);
    GLuint fragment = 0;
    try {
        fragment =
            compileShader(GL_FRAGMENT_SHADER, sources.load(fragmentPath, defines), fragmentPath);
    } catch (...) {
        glDeleteShader(vertex);
        throw;
    }
    const GLuint shaders[] = {vertex, fragment};
    return Program(linkProgram(shaders, vertexPath));
}

void Program::dispatch1D(std::uint64_t count, std::uint32_t groupSize) {
    const std::uint64_t groups = (count + groupSize - 1) / groupSize;
    if (groups > 0) {
        glDispatchCompute(static_cast<GLuint>(groups), 1, 1);
    }
}

void Program::dispatch2D(int width, int height, int groupSizeX, int groupSizeY) {
    glDispatchCompute(static_cast<GLuint>((width + groupSizeX - 1) / groupSizeX),
                      static_cast<GLuint>((height + groupSizeY - 1) / groupSizeY), 1);
}

// ---- Framebuffer, VertexArray, TimerQuery -------------------------------------------------

Framebuffer::Framebuffer(std::span<const Texture* const> colors, const Texture* depth,
                         std::string_view labelText) {
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    name_ = GlName<FramebufferTraits>(id);
    std::vector<GLenum> drawBuffers;
    for (std::size_t i = 0; i < colors.size(); ++i) {
        const GLenum attachment = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i);
        glNamedFramebufferTexture(id, attachment, colors[i]->id(), 0);
        drawBuffers.push_back(attachment);
    }
    glNamedFramebufferDrawBuffers(id, static_cast<GLsizei>(drawBuffers.size()), drawBuffers.data());
    if (depth != nullptr) {
        glNamedFramebufferTexture(id, GL_DEPTH_ATTACHMENT, depth->id(), 0);
    }
    const GLenum status = glCheckNamedFramebufferStatus(id, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        throw Error(
            fmt::format("the framebuffer '{}' is incomplete (0x{:04x})", labelText, status));
    }
    label(GL_FRAMEBUFFER, id, labelText);
}

VertexArray::VertexArray() {
    GLuint id = 0;
    glCreateVertexArrays(1, &id);
    name_ = GlName<VertexArrayTraits>(id);
}

TimerQuery::TimerQuery() {
    GLuint id = 0;
    glCreateQueries(GL_TIME_ELAPSED, 1, &id);
    name_ = GlName<QueryTraits>(id);
}

}  // namespace subscan
