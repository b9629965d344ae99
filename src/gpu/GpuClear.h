#pragma once

#include <cstdint>
#include <map>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "gpu/GlContext.h"
#include "gpu/GlObjects.h"
#include "gpu/ShaderSources.h"

namespace subscan {

/// Who clears buffers and textures: Auto takes a compute shader on GPUs and the driver's clear
/// on software renderers; the others force one (tests, bench).
enum class ClearPath { Auto, Driver, Compute };

/// Clears buffers and textures to one value. The driver's clears (glClearNamedBufferData,
/// glClearTexImage, framebuffer clears) run far below a GPU's memory bandwidth on some GPUs —
/// the H200: 31 GB/s for a buffer and 56 GB/s for a texture, against 1.1–1.5 TB/s for a compute
/// shader writing the same bytes (subscan_gl_ops_bench, bench/README) — so there a compute
/// shader (gpu/GpuClear.comp) does it. On llvmpipe the driver's clear is a memset and a compute
/// dispatch the slow path (16 MB: 0.4 against 4.7 ms), so software renderers keep it.
///
/// The compute path rebinds image unit SUBSCAN_IMAGE_OUT0 (a pass clears before it binds its
/// images) and ends with a barrier, so that what follows sees the cleared values.
class GpuClear {
  public:
    GpuClear(ShaderSources sources, const GlCapabilities& capabilities);

    /// Every texel of `texture` to `value` (as many components as its format has).
    void texture(Texture& texture, const glm::vec4& value, ClearPath path);
    /// The texels [origin, origin + size) of `texture` to `value` (inside the texture).
    void textureRegion(Texture& texture, glm::ivec2 origin, glm::ivec2 size, const glm::vec4& value,
                       ClearPath path);
    /// Every texel of an R32UI texture to `value`.
    void textureUint(Texture& texture, std::uint32_t value, ClearPath path);
    /// Every 32-bit word of `buffer` to `value`.
    void buffer(Buffer& buffer, std::uint32_t value, ClearPath path);

    /// Whether `path` clears by compute shader on this context.
    bool byCompute(ClearPath path) const;

  private:
    const Program& program(TextureFormat format);
    const Program& bufferProgram();
    /// Runs the image program in use over the texels [origin, origin + size) of `texture`.
    void store(Texture& texture, glm::ivec2 origin, glm::ivec2 size);

    ShaderSources sources_;
    bool software_;
    std::map<TextureFormat, Program> imagePrograms_;  // compiled on first use
    Program bufferProgram_;
};

}  // namespace subscan
