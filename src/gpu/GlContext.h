#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace subscan {

/// What the current OpenGL implementation offers, queried once after context creation.
struct GlCapabilities {
    std::string vendor;
    std::string renderer;
    std::string version;
    /// llvmpipe, softpipe, swrast: timer queries are not meaningful, glFinish + CPU clock is.
    bool software = false;
    /// GL_NV_shader_atomic_int64 (+ GL_ARB_gpu_shader_int64): the one-pass 64-bit rasterizer.
    bool int64Atomics = false;
    /// The largest range one shader storage block may bind (bytes).
    std::uint64_t maxStorageBlockBytes = 0;
    /// Texels one buffer texture may hold (GL_MAX_TEXTURE_BUFFER_SIZE); point data is chunked
    /// below it.
    std::uint64_t maxTextureBufferTexels = 0;
    int maxComputeWorkGroupsX = 0;
    int maxTextureSize = 0;
};

/// A current OpenGL 4.5 core context, however it was made (EGL headless, or a GLFW window).
/// Not copyable; the context is destroyed with the object.
class GlContext {
  public:
    virtual ~GlContext() = default;
    GlContext() = default;
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;

    virtual void makeCurrent() = 0;
    const GlCapabilities& capabilities() const { return capabilities_; }

    /// GL debug-output errors (KHR_debug) since the last call, then cleared. Empty when debug
    /// output was not requested.
    std::vector<std::string> takeDebugErrors();

    /// Throws subscan::Error naming the first error takeDebugErrors() returns, if any: what a
    /// command calls once its GL work is done, so an error outside the passes fails it too.
    void throwOnErrors(std::string_view during);

  protected:
    /// Call once the context is current: fills capabilities() and installs debug output.
    void initialize(bool debugOutput);

  private:
    GlCapabilities capabilities_;
    std::vector<std::string> debugErrors_;
};

struct HeadlessContextOptions {
    /// Prefer a hardware EGL device; false picks Mesa's software rasterizer even with a GPU.
    bool preferHardware = true;
    /// Record GL errors from KHR_debug (tests and debug builds turn this on).
    bool debugOutput = false;
};

/// Whether a program should ask for GL debug output: in debug builds, and wherever the
/// environment sets SUBSCAN_GL_DEBUG to 1 (the tests set it, since they run Release builds).
bool glDebugOutputRequested();

/// An OpenGL 4.5 core context without any window or display: an EGL device (hardware first)
/// through EGL_EXT_platform_device, else Mesa's surfaceless platform (llvmpipe). Throws
/// subscan::Error with one sentence when no usable OpenGL 4.5 exists.
std::unique_ptr<GlContext> createHeadlessContext(const HeadlessContextOptions& options = {});

}  // namespace subscan
