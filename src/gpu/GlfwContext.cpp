// A window with an OpenGL 4.5 core context through GLFW, for the interactive viewer.
#include "gpu/GlfwContext.h"

#include <algorithm>
#include <cstdlib>
#include <string>
#include <utility>

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <fmt/format.h>

#include "core/Error.h"
#include "gpu/GlObjects.h"

namespace subscan {

namespace {

/// GLFW's description of its most recent error, or a fallback when it recorded none.
std::string lastGlfwError(int* code = nullptr) {
    const char* description = nullptr;
    const int error = glfwGetError(&description);
    if (code != nullptr) {
        *code = error;
    }
    return description != nullptr ? description : "no reason given";
}

}  // namespace

GlfwSession::GlfwSession() {
    // GLFW on Debian talks to X11 only; without DISPLAY it can only fail, so say why directly.
    const char* display = std::getenv("DISPLAY");
    if (display == nullptr || *display == '\0') {
        throw Error(
            "cannot open a window: no display (set DISPLAY, or use `subscan render` headless)");
    }
    if (glfwInit() != GLFW_TRUE) {
        throw Error(fmt::format(
            "cannot open a window: cannot connect to the display '{}' ({}); use `subscan render` "
            "headless",
            display, lastGlfwError()));
    }
    active_ = true;
}

GlfwSession::~GlfwSession() {
    if (active_) {
        glfwTerminate();
    }
}

GlfwSession::GlfwSession(GlfwSession&& other) noexcept
    : active_(std::exchange(other.active_, false)) {}

GlfwSession& GlfwSession::operator=(GlfwSession&& other) noexcept {
    if (this != &other) {
        if (active_) {
            glfwTerminate();
        }
        active_ = std::exchange(other.active_, false);
    }
    return *this;
}

void GlfwWindowDeleter::operator()(GLFWwindow* window) const {
    glfwDestroyWindow(window);
}

GlfwContext::GlfwContext(const WindowOptions& options) {
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, options.debugOutput ? GLFW_TRUE : GLFW_FALSE);
    // The pipeline encodes sRGB itself; the window must store its bytes unchanged.
    glfwWindowHint(GLFW_SRGB_CAPABLE, GLFW_FALSE);
    glfwWindowHint(GLFW_DEPTH_BITS, 0);
    glfwWindowHint(GLFW_STENCIL_BITS, 0);
    window_.reset(
        glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr, nullptr));
    if (!window_) {
        int code = 0;
        const std::string reason = lastGlfwError(&code);
        if (code == GLFW_VERSION_UNAVAILABLE || code == GLFW_API_UNAVAILABLE) {
            throw Error(
                fmt::format("cannot open a window: the display offers no OpenGL 4.5 core "
                            "context ({}); use `subscan render` headless",
                            reason));
        }
        throw Error(fmt::format("cannot open a window: {}", reason));
    }
    makeCurrent();
    // Presenting never waits for the screen refresh longer than one interval.
    glfwSwapInterval(1);
    initialize(options.debugOutput);
}

GlfwContext::~GlfwContext() {
    glfwMakeContextCurrent(nullptr);
}

void GlfwContext::makeCurrent() {
    glfwMakeContextCurrent(window_.get());
}

glm::ivec2 GlfwContext::framebufferSize() const {
    glm::ivec2 size{0};
    glfwGetFramebufferSize(window_.get(), &size.x, &size.y);
    return size;
}

glm::dvec2 GlfwContext::windowToFramebufferScale() const {
    int windowWidth = 0, windowHeight = 0;
    glfwGetWindowSize(window_.get(), &windowWidth, &windowHeight);
    const glm::ivec2 framebuffer = framebufferSize();
    if (windowWidth <= 0 || windowHeight <= 0) {
        return glm::dvec2(1.0);
    }
    return glm::dvec2(framebuffer) / glm::dvec2(windowWidth, windowHeight);
}

void GlfwContext::swapBuffers() {
    glfwSwapBuffers(window_.get());
}

void GlfwContext::clearWindow(const glm::vec3& srgbColor) {
    const glm::ivec2 size = framebufferSize();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, size.x, size.y);
    const GLfloat color[4] = {srgbColor.r, srgbColor.g, srgbColor.b, 1.0f};
    glClearNamedFramebufferfv(0, GL_COLOR, 0, color);
}

void GlfwContext::presentImage(const Texture& image) {
    const glm::ivec2 size = framebufferSize();
    // A framebuffer object made for this one copy: the pipeline recreates "image" whenever the
    // size changes, and an attachment would keep a deleted texture's storage alive.
    GLuint id = 0;
    glCreateFramebuffers(1, &id);
    const GlName<FramebufferTraits> source(id);
    glNamedFramebufferTexture(source.id(), GL_COLOR_ATTACHMENT0, image.id(), 0);
    glNamedFramebufferReadBuffer(source.id(), GL_COLOR_ATTACHMENT0);
    // The image's row 0 is its top row, a window's row 0 its bottom row: copy upside down.
    glBlitNamedFramebuffer(source.id(), 0, 0, 0, image.width(), image.height(), 0, size.y, size.x,
                           0, GL_COLOR_BUFFER_BIT, GL_NEAREST);
}

Image8 GlfwContext::readBackBuffer() const {
    const glm::ivec2 size = framebufferSize();
    Image8 image{size.x, size.y, 4,
                 std::vector<std::uint8_t>(4u * static_cast<std::size_t>(size.x) *
                                           static_cast<std::size_t>(size.y))};
    if (image.pixels.empty()) {
        return image;
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, size.x, size.y, GL_RGBA, GL_UNSIGNED_BYTE, image.pixels.data());
    // Bottom-up rows to top-down, and an opaque alpha: the window is opaque whatever its
    // visual stores in the alpha channel.
    const std::size_t rowBytes = 4u * static_cast<std::size_t>(size.x);
    std::uint8_t* const pixels = image.pixels.data();
    for (std::size_t top = 0, bottom = static_cast<std::size_t>(size.y) - 1; top < bottom;
         ++top, --bottom) {
        std::swap_ranges(pixels + top * rowBytes, pixels + (top + 1) * rowBytes,
                         pixels + bottom * rowBytes);
    }
    for (std::size_t alpha = 3; alpha < image.pixels.size(); alpha += 4) {
        image.pixels[alpha] = 255;
    }
    return image;
}

}  // namespace subscan
