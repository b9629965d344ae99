#pragma once

// Move-only RAII wrappers over OpenGL 4.5 objects, created and used through direct state access
// (no bind-to-edit). Each object carries a debug label so GPU debuggers show names.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <epoxy/gl.h>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

namespace subscan {

class ShaderSources;

/// Owns one GL object name; `Traits::destroy(GLuint)` deletes it.
template <class Traits>
class GlName {
  public:
    GlName() = default;
    explicit GlName(GLuint id) : id_(id) {}
    ~GlName() {
        if (id_ != 0) {
            Traits::destroy(id_);
        }
    }
    GlName(GlName&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
    GlName& operator=(GlName&& other) noexcept {
        if (this != &other) {
            if (id_ != 0) {
                Traits::destroy(id_);
            }
            id_ = std::exchange(other.id_, 0);
        }
        return *this;
    }
    GlName(const GlName&) = delete;
    GlName& operator=(const GlName&) = delete;

    GLuint id() const { return id_; }
    explicit operator bool() const { return id_ != 0; }

  private:
    GLuint id_ = 0;
};

struct BufferTraits {
    static void destroy(GLuint id) { glDeleteBuffers(1, &id); }
};
struct TextureTraits {
    static void destroy(GLuint id) { glDeleteTextures(1, &id); }
};
struct ProgramTraits {
    static void destroy(GLuint id) { glDeleteProgram(id); }
};
struct FramebufferTraits {
    static void destroy(GLuint id) { glDeleteFramebuffers(1, &id); }
};
struct VertexArrayTraits {
    static void destroy(GLuint id) { glDeleteVertexArrays(1, &id); }
};
struct QueryTraits {
    static void destroy(GLuint id) { glDeleteQueries(1, &id); }
};

enum class TextureFormat { R32F, RG32F, RGBA16F, RGBA32F, RGBA8, R32UI, R8, Depth32F };

/// Immutable-storage buffer (glNamedBufferStorage) that can be updated and read back; or a
/// read-only view of the caller's memory (borrowing()).
class Buffer {
  public:
    Buffer() = default;
    /// `data` may be null (contents undefined until written). Throws subscan::Error when the
    /// driver cannot allocate it.
    Buffer(std::size_t bytes, const void* data, std::string_view label);

    template <class T>
    static Buffer fromSpan(std::span<const T> values, std::string_view label) {
        return Buffer(values.size_bytes(), values.data(), label);
    }
    /// A buffer over the caller's memory instead of a copy of it (GL_AMD_pinned_memory, as
    /// Mesa's llvmpipe offers it for any address; radeonsi only pins whole pages): the GPU
    /// reads `data` in place, so it must stay alive and unchanged while the buffer lives;
    /// upload() and fill() refuse it. An empty buffer (id 0) where the driver refuses: no such
    /// extension, or memory it cannot pin (then no GL error or debug message remains).
    static Buffer borrowing(const void* data, std::size_t bytes, std::string_view label);

    GLuint id() const { return name_.id(); }
    std::size_t size() const { return size_; }
    explicit operator bool() const { return static_cast<bool>(name_); }
    /// Made by borrowing(): the GPU reads the caller's memory.
    bool borrowed() const { return borrowed_; }

    /// upload() and fill() throw subscan::Error for a borrowed buffer (the caller's memory).
    void upload(std::size_t offset, std::size_t bytes, const void* data);
    void download(std::size_t offset, std::size_t bytes, void* data) const;
    /// Fills every 32-bit word with `value`.
    void fill(std::uint32_t value);

    void bindStorage(GLuint binding) const;
    void bindUniform(GLuint binding) const;
    /// Binds the buffer to texture unit `unit` as a buffer texture of `format` texels (a
    /// samplerBuffer or usamplerBuffer read with texelFetch). On llvmpipe a texel fetch is a
    /// vector gather, while a storage buffer load is one guarded scalar load per lane, so
    /// passes read pyramids this way and write them as storage buffers. Throws subscan::Error
    /// when the buffer holds more texels than the driver's buffer textures may.
    void bindTexels(GLuint unit, TextureFormat format) const;

    template <class T>
    std::vector<T> read() const {
        std::vector<T> values(size_ / sizeof(T));
        download(0, values.size() * sizeof(T), values.data());
        return values;
    }

  private:
    void refuseWritesIfBorrowed() const;

    GlName<BufferTraits> name_;
    std::size_t size_ = 0;
    bool borrowed_ = false;
    std::string label_;
    // A cache, not state: made by the first bindTexels (again when the format changes).
    mutable GlName<TextureTraits> texelView_;
    mutable TextureFormat texelFormat_ = TextureFormat::R32F;
};

/// A uniform buffer holding exactly one T (a struct from shaders/shared/bindings.h).
template <class T>
class UniformBlock {
  public:
    explicit UniformBlock(std::string_view label) : buffer_(sizeof(T), nullptr, label) {}
    void set(const T& value) { buffer_.upload(0, sizeof(T), &value); }
    void bind(GLuint binding) const { buffer_.bindUniform(binding); }

  private:
    Buffer buffer_;
};

/// 2-D texture with immutable storage and a single level. (Image pyramids live in storage
/// buffers instead: GL mip levels are floor(W / 2^R) wide, the pipeline's levels ceil(W / 2^R).)
class Texture {
  public:
    Texture() = default;
    Texture(TextureFormat format, int width, int height, std::string_view label);

    GLuint id() const { return name_.id(); }
    TextureFormat format() const { return format_; }
    int width() const { return width_; }
    int height() const { return height_; }
    int channels() const;

    void bindImage(GLuint unit, GLenum access) const;
    /// Binds an R32F or R32UI texture as an r32ui image: the raw bits of each texel, for
    /// atomics on float bits (positive floats order like their bit patterns).
    void bindImageBits(GLuint unit, GLenum access) const;
    void bindSampler(GLuint unit) const;
    /// Sets every texel to `value` (as many components as the format has).
    void clear(const glm::vec4& value = glm::vec4(0.0f));
    /// Sets the texels [origin, origin + size) to `value`.
    void clearRegion(glm::ivec2 origin, glm::ivec2 size, const glm::vec4& value);
    /// Sets every texel of an R32UI texture to `value`.
    void clearUint(std::uint32_t value);

    /// Texel values, row 0 first, `channels()` per texel (RGBA8 and R8 come back normalised to
    /// 0..1 by readFloats).
    std::vector<float> readFloats() const;
    std::vector<std::uint32_t> readUints() const;
    std::vector<std::uint8_t> readRgba8() const;
    void uploadFloats(std::span<const float> values);

  private:
    GlName<TextureTraits> name_;
    TextureFormat format_ = TextureFormat::RGBA8;
    int width_ = 0;
    int height_ = 0;
};

/// A linked shader program built from embedded sources.
class Program {
  public:
    Program() = default;
    static Program compute(const ShaderSources& sources, std::string_view path,
                           std::string_view defines = {});
    static Program graphics(const ShaderSources& sources, std::string_view vertexPath,
                            std::string_view fragmentPath, std::string_view defines = {});

    GLuint id() const { return name_.id(); }
    void use() const { glUseProgram(name_.id()); }
    /// glDispatchCompute with enough groups of `groupSize` to cover `count` threads along x.
    static void dispatch1D(std::uint64_t count, std::uint32_t groupSize);
    static void dispatch2D(int width, int height, int groupSizeX, int groupSizeY);

  private:
    explicit Program(GLuint id) : name_(id) {}
    GlName<ProgramTraits> name_;
};

class Framebuffer {
  public:
    Framebuffer() = default;
    /// Colour attachments in order, plus an optional depth texture; checks completeness.
    Framebuffer(std::span<const Texture* const> colors, const Texture* depth,
                std::string_view label);
    GLuint id() const { return name_.id(); }

  private:
    GlName<FramebufferTraits> name_;
};

class VertexArray {
  public:
    VertexArray();
    GLuint id() const { return name_.id(); }

  private:
    GlName<VertexArrayTraits> name_;
};

/// GL_TIME_ELAPSED query.
class TimerQuery {
  public:
    TimerQuery();
    GLuint id() const { return name_.id(); }

  private:
    GlName<QueryTraits> name_;
};

}  // namespace subscan
