#pragma once

#include <memory>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "gpu/GlContext.h"
#include "io/Image.h"

struct GLFWwindow;

namespace subscan {

class Texture;

struct WindowOptions {
    int width = 1280;
    int height = 800;
    std::string title = "subscan";
    /// Record GL errors from KHR_debug (debug builds turn this on).
    bool debugOutput = false;
};

/// Owns GLFW's library state: glfwInit on construction, glfwTerminate on destruction. GLFW
/// allows one such session per process at a time.
class GlfwSession {
  public:
    /// Throws subscan::Error when GLFW cannot start (no display, no X server).
    GlfwSession();
    ~GlfwSession();
    GlfwSession(GlfwSession&& other) noexcept;
    GlfwSession& operator=(GlfwSession&& other) noexcept;
    GlfwSession(const GlfwSession&) = delete;
    GlfwSession& operator=(const GlfwSession&) = delete;

  private:
    bool active_ = false;
};

struct GlfwWindowDeleter {
    void operator()(GLFWwindow* window) const;
};
using GlfwWindowHandle = std::unique_ptr<GLFWwindow, GlfwWindowDeleter>;

/// An OpenGL 4.5 core context with a window on the screen (GLFW). The frame pipeline renders
/// into its own textures as it does headless; presentImage() then copies the final image into
/// the window's back buffer, where the user interface is drawn on top.
class GlfwContext final : public GlContext {
  public:
    /// Throws subscan::Error with one sentence when there is no display or no OpenGL 4.5 core.
    explicit GlfwContext(const WindowOptions& options);
    ~GlfwContext() override;

    void makeCurrent() override;

    GLFWwindow* window() const { return window_.get(); }
    /// The window's drawable size in pixels (differs from the window size on high-DPI screens).
    glm::ivec2 framebufferSize() const;
    /// Window coordinates (what cursor positions are in) to framebuffer pixels.
    glm::dvec2 windowToFramebufferScale() const;
    void swapBuffers();

    /// Fills the back buffer with `srgbColor` (already sRGB-encoded, as the pipeline writes).
    void clearWindow(const glm::vec3& srgbColor);
    /// Copies an RGBA8 image whose row 0 is the top row (the pipeline's "image") to the whole back
    /// buffer, scaling when the sizes differ.
    void presentImage(const Texture& image);
    /// What the back buffer holds now, RGBA8, row 0 at the top: the window as the user sees it
    /// after the next swap, user interface included.
    Image8 readBackBuffer() const;

  private:
    GlfwSession session_;
    GlfwWindowHandle window_;
};

}  // namespace subscan
