#pragma once

struct GLFWwindow;

namespace subscan::viewer {

/// Dear ImGui for one GLFW window with an OpenGL 3+ context: the ImGui context and its GLFW and
/// OpenGL 3 backends, shut down in reverse order on destruction. The backends' own GLFW
/// callbacks are not installed: the viewer owns the callbacks and forwards events (so that it
/// can tell which ones the panel took).
class ImGuiSession {
  public:
    explicit ImGuiSession(GLFWwindow* window);
    ~ImGuiSession();
    ImGuiSession(const ImGuiSession&) = delete;
    ImGuiSession& operator=(const ImGuiSession&) = delete;

    void beginFrame();
    /// Draws what was built since beginFrame() into the bound framebuffer.
    void endFrame();
};

}  // namespace subscan::viewer
