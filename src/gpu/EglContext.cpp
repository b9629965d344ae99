// Headless OpenGL through EGL: a hardware EGL device when there is one, Mesa's software
// rasterizer (llvmpipe) otherwise. No window system, no display server.
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include <epoxy/egl.h>
#include <fmt/format.h>

#include "core/Error.h"
#include "gpu/GlContext.h"

namespace subscan {

namespace {

bool hasWord(const char* list, const char* word) {
    if (list == nullptr) {
        return false;
    }
    const std::size_t length = std::strlen(word);
    for (const char* p = std::strstr(list, word); p != nullptr; p = std::strstr(p + 1, word)) {
        const bool startOk = p == list || p[-1] == ' ';
        const bool endOk = p[length] == '\0' || p[length] == ' ';
        if (startOk && endOk) {
            return true;
        }
    }
    return false;
}

/// EGL displays are process-wide: eglGetPlatformDisplay returns the same display for the same
/// device, and eglTerminate is not counted (Mesa 22 lacks EGL_KHR_display_reference), so
/// terminating the display when one context goes would destroy every other context on it (two
/// renderers in one process, as the Python module allows). So the contexts count their users of
/// each display, under a lock because contexts may be made and dropped on any thread, and the
/// last one terminates it. Function-local: this mirrors EGL's own process-wide state.
class DisplayUsers {
  public:
    /// eglInitialize, counted; false (with eglGetError() set) when it fails.
    static bool initialize(EGLDisplay display) {
        DisplayUsers& users = instance();
        const std::lock_guard lock(users.mutex_);
        EGLint major = 0, minor = 0;
        if (eglInitialize(display, &major, &minor) != EGL_TRUE) {
            return false;
        }
        ++users.count_[display];
        return true;
    }
    /// The counterpart of a successful initialize(): eglTerminate once no user is left.
    static void release(EGLDisplay display) {
        DisplayUsers& users = instance();
        const std::lock_guard lock(users.mutex_);
        const auto found = users.count_.find(display);
        if (found != users.count_.end() && --found->second == 0) {
            users.count_.erase(found);
            eglTerminate(display);
        }
    }

  private:
    static DisplayUsers& instance() {
        static DisplayUsers users;
        return users;
    }
    std::mutex mutex_;
    std::map<EGLDisplay, int> count_;
};

class EglContext final : public GlContext {
  public:
    EglContext(EGLDisplay display, EGLContext context, bool debugOutput)
        : display_(display), context_(context) {
        makeCurrent();
        initialize(debugOutput);
    }
    ~EglContext() override {
        // Only our own context: another one current on this thread stays current.
        if (eglGetCurrentContext() == context_) {
            eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        }
        eglDestroyContext(display_, context_);
        DisplayUsers::release(display_);
    }
    void makeCurrent() override {
        if (eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE) {
            throw Error(fmt::format("cannot make the OpenGL context current (EGL error 0x{:x})",
                                    eglGetError()));
        }
    }

  private:
    EGLDisplay display_;
    EGLContext context_;
};

/// Initialises `display` and creates a 4.5 core context on it without surfaces; empty string
/// on success, else why not.
std::string tryCreateContext(EGLDisplay display, bool debugOutput, EGLContext& context) {
    if (display == EGL_NO_DISPLAY) {
        return "no EGL display";
    }
    if (!DisplayUsers::initialize(display)) {
        return fmt::format("eglInitialize failed (0x{:x})", eglGetError());
    }
    const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
    if (!hasWord(extensions, "EGL_KHR_surfaceless_context") ||
        !hasWord(extensions, "EGL_KHR_create_context")) {
        DisplayUsers::release(display);
        return "the EGL display cannot make surfaceless OpenGL contexts";
    }
    if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
        DisplayUsers::release(display);
        return "the EGL display has no desktop OpenGL";
    }
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!hasWord(extensions, "EGL_KHR_no_config_context")) {
        const EGLint wanted[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint found = 0;
        if (eglChooseConfig(display, wanted, &config, 1, &found) != EGL_TRUE || found == 0) {
            DisplayUsers::release(display);
            return "no EGL config supports OpenGL";
        }
    }
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                 4,
                                 EGL_CONTEXT_MINOR_VERSION,
                                 5,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                 EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                 EGL_CONTEXT_OPENGL_DEBUG,
                                 debugOutput ? EGL_TRUE : EGL_FALSE,
                                 EGL_NONE};
    context = eglCreateContext(display, config, EGL_NO_CONTEXT, attributes);
    if (context == EGL_NO_CONTEXT) {
        const EGLint error = eglGetError();
        DisplayUsers::release(display);
        return fmt::format("no OpenGL 4.5 core context (EGL error 0x{:x})", error);
    }
    return {};
}

}  // namespace

std::unique_ptr<GlContext> createHeadlessContext(const HeadlessContextOptions& options) {
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (client == nullptr || !hasWord(client, "EGL_EXT_platform_base")) {
        throw Error(
            "no usable OpenGL: EGL with platform extensions is not available (install "
            "libegl1 and Mesa's libegl-mesa0 and libgl1-mesa-dri)");
    }
    std::vector<std::string> failures;
    // A context on `display`, or null with the reason recorded.
    auto attempt = [&](EGLDisplay display) -> std::unique_ptr<GlContext> {
        EGLContext context = EGL_NO_CONTEXT;
        std::string failure = tryCreateContext(display, options.debugOutput, context);
        if (failure.empty()) {
            return std::make_unique<EglContext>(display, context, options.debugOutput);
        }
        failures.push_back(std::move(failure));
        return nullptr;
    };

    // 1. EGL devices, hardware first (EGL_MESA_device_software marks llvmpipe's device).
    if (hasWord(client, "EGL_EXT_device_enumeration") &&
        hasWord(client, "EGL_EXT_platform_device")) {
        EGLint count = 0;
        eglQueryDevicesEXT(0, nullptr, &count);
        std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
        eglQueryDevicesEXT(count, devices.data(), &count);
        for (const bool wantSoftware : {false, true}) {
            if (!wantSoftware && !options.preferHardware) {
                continue;
            }
            for (EGLDeviceEXT device : devices) {
                const bool software = hasWord(eglQueryDeviceStringEXT(device, EGL_EXTENSIONS),
                                              "EGL_MESA_device_software");
                if (software != wantSoftware) {
                    continue;
                }
                if (auto context = attempt(
                        eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, device, nullptr))) {
                    return context;
                }
            }
        }
    }
    // 2. Mesa's surfaceless platform.
    if (hasWord(client, "EGL_MESA_platform_surfaceless")) {
        if (auto context = attempt(eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA,
                                                            EGL_DEFAULT_DISPLAY, nullptr))) {
            return context;
        }
    }
    throw Error(
        fmt::format("no usable OpenGL 4.5: {} (for software rendering install Mesa's "
                    "libegl-mesa0 and libgl1-mesa-dri)",
                    failures.empty() ? "no EGL device or surfaceless platform" : failures.back()));
}

}  // namespace subscan
