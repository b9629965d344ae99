#include "app/viewer/Viewer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <new>
#include <utility>

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <fmt/format.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "core/SensorView.h"
#include "io/CameraJson.h"
#include "io/Image.h"
#include "render/ReducedResolution.h"
#include "render/Renderer.h"

namespace subscan::viewer {

namespace {

/// The eye and target of the scan's sensor view (viewFromSensor), the target at the depth of
/// the points' middle; nothing when the scan records no sensor.
std::optional<std::pair<glm::dvec3, glm::dvec3>> sensorLook(const LoadedScan& scan, UpAxis up) {
    std::vector<std::string> warnings;
    Camera camera;
    try {
        camera = viewFromSensor(scan.cloud, scan.grid, scan.sensor, up, 640, 480, false,
                                ViewerCamera::kFovyDegrees, warnings);
    } catch (const Error&) {
        return std::nullopt;
    }
    const glm::dvec3 eye = camera.eye();
    const glm::dvec3 forward =
        glm::normalize(glm::dvec3(glm::inverse(camera.view) * glm::dvec4(0, 0, -1, 0)));
    const glm::dvec3 middle = framingBounds(scan.cloud).center();
    const double depth = glm::dot(middle - eye, forward);
    return std::pair{eye, eye + forward * (depth > 0.0 ? depth : glm::length(middle - eye))};
}

// Two left presses this close in time and space are a double click.
constexpr double kDoubleClickSeconds = 0.35;
constexpr double kDoubleClickPixels = 4.0;
// How far around the cursor a pick or zoom looks for the surface: 1-pixel points leave gaps.
constexpr int kPickRadiusPixels = 3;
// Fly speed: crossing the scene's bounding sphere takes 4 s (Shift: 1 s).
constexpr double kFlyRadiiPerSecond = 0.5;
constexpr double kFlyShiftFactor = 4.0;
// A stalled frame (a slow software render) must not turn into a jump.
constexpr double kMaxFlyStepSeconds = 0.25;
// Idle: wake up now and then even without events; loading: redraw the progress bar smoothly.
constexpr double kIdleWaitSeconds = 0.25;
constexpr double kLoadingWaitSeconds = 1.0 / 30.0;
/// A streamed scan loads the nodes of a view once the camera has rested this long.
constexpr double kRefineAfterRestSeconds = 0.3;
// A script's resize waits this long for the window system.
constexpr double kResizeTimeoutSeconds = 2.0;

template <class... Visitors>
struct Overloaded : Visitors... {
    using Visitors::operator()...;
};
// Clang 14 (the sanitized build) deduces an aggregate's template arguments only through a guide.
template <class... Visitors>
Overloaded(Visitors...) -> Overloaded<Visitors...>;

bool sameCamera(const Camera& a, const Camera& b) {
    return a.width == b.width && a.height == b.height && a.fovyDegrees == b.fovyDegrees &&
           a.nearPlane == b.nearPlane && a.farPlane == b.farPlane && a.view == b.view;
}

/// NAME.png -> NAME.camera.json and the like.
std::filesystem::path sidecarPath(const std::filesystem::path& image, std::string_view suffix) {
    std::filesystem::path path = image;
    path.replace_extension();
    path += suffix;
    return path;
}

WindowOptions windowOptions(const ViewerOptions& options) {
    WindowOptions window;
    window.width = options.width;
    window.height = options.height;
    window.title = "subscan: " + options.source;
    window.debugOutput = glDebugOutputRequested();  // GL errors become errors, as in the CLI
    return window;
}

}  // namespace

RenderSettings viewerDefaultSettings() {
    RenderSettings settings;
    settings.temporal.enabled = true;
    return settings;
}

Viewer::Viewer(ViewerOptions options)
    : options_(std::move(options)),
      unattended_(!options_.script.empty() || options_.exitAfterFrames.has_value()),
      context_(windowOptions(options_)),
      imgui_(context_.window()),
      crossFade_(ShaderSources()),
      settings_(options_.settings),
      scattering_(options_.settings.scattering),
      showPanel_(options_.showPanel) {
    const GlCapabilities& capabilities = context_.capabilities();
    status_.glRenderer = fmt::format("OpenGL {} | {}", capabilities.version, capabilities.renderer);
    status_.int64Atomics = capabilities.int64Atomics;
    installCallbacks();
}

Viewer::~Viewer() = default;

int Viewer::run() {
    startLoading(options_.source);
    warmUpRenderer();
    lastFrameTime_ = glfwGetTime();
    for (;;) {
        waitForEvents();
        bool exiting = exitRequested_ || glfwWindowShouldClose(context_.window()) == GLFW_TRUE;
        if (pendingOpen_) {
            startLoading(*std::exchange(pendingOpen_, std::nullopt));
        } else if (!loading_ && levelsOfDetailChanged()) {
            reopenForLevelsOfDetail();
        }
        finishLoading();
        finishCompleting();
        refineStreamedView();
        continueArrival();

        const double now = glfwGetTime();
        const double seconds = now - lastFrameTime_;
        lastFrameTime_ = now;
        if (renderer_ && !awaitingScan() && !exiting) {
            runScript();
            flyWithKeys(seconds);
        }
        // After the script's changes: a frame whose camera or settings it changed waits, with
        // its screenshots, for the nodes or the scan they need.
        const bool showing = renderer_ != nullptr && !awaitingScan();
        exiting = exiting || exitRequested_ ||
                  (showing && options_.exitAfterFrames && frame_ + 1 >= *options_.exitAfterFrames);

        drawFrame();
        if (showing || exiting) {
            for (const std::filesystem::path& path : std::exchange(pendingScreenshots_, {})) {
                writeScreenshot(path);
            }
        }
        if (exiting && !options_.screenshotAtExit.empty()) {
            writeScreenshot(options_.screenshotAtExit);
        }
        context_.swapBuffers();
        recordOpeningTimes();
        if (showing) {
            ++frame_;
        }
        if (exiting) {
            const auto timeOf = [](double value) {
                return value > 0.0 ? fmt::format("{:.2f} s", value) : std::string("not yet");
            };
            if (unattended_ && !streamed_) {
                fmt::print(stderr,
                           "subscan: {}: first picture {} after opening, with its local spacing "
                           "and normals {}\n",
                           status_.scanSource, timeOf(status_.firstPictureSeconds),
                           timeOf(status_.viewCompleteSeconds));
            } else if (unattended_) {
                const lod::CachedNodeSource::Usage cache = streamed_->usage();
                fmt::print(stderr,
                           "subscan: {}: first picture {} after opening, the view's nodes {}; "
                           "node cache {:.0f} of {:.0f} MiB, {} node loads read the file, {} "
                           "did not; {} frames uploaded nodes\n",
                           status_.scanSource, timeOf(status_.firstPictureSeconds),
                           timeOf(status_.viewCompleteSeconds), cache.bytes / 1048576.0,
                           streamed_->byteBudget() / 1048576.0, cache.misses, cache.hits,
                           uploadFrames_);
            }
            return 0;
        }
    }
}

// ---- events ----------------------------------------------------------------------------------

Viewer& Viewer::of(GLFWwindow* window) {
    return *static_cast<Viewer*>(glfwGetWindowUserPointer(window));
}

void Viewer::installCallbacks() {
    GLFWwindow* window = context_.window();
    glfwSetWindowUserPointer(window, this);
    glfwSetMouseButtonCallback(window, onMouseButton);
    glfwSetCursorPosCallback(window, onCursorPosition);
    glfwSetScrollCallback(window, onScroll);
    glfwSetKeyCallback(window, onKey);
    glfwSetCharCallback(window, onChar);
    glfwSetDropCallback(window, onDrop);
    glfwSetWindowFocusCallback(window, onFocus);
    glfwSetCursorEnterCallback(window, onCursorEnter);
}

void Viewer::waitForEvents() {
    if (loading_ || refining_ || completing_ || dueRefinement()) {
        glfwWaitEventsTimeout(kLoadingWaitSeconds);
    } else if (unattended_ || flying_ || arriving_ || frameIsStale() || fading()) {
        // An upload under way goes on at every frame, not every idle wait.
        // A change made while drawing the last frame (the panel, a script) shows at once.
        glfwPollEvents();
    } else {
        glfwWaitEventsTimeout(kIdleWaitSeconds);
    }
    // Errors inside callbacks could not cross GLFW's C frames; they surface here.
    if (callbackError_) {
        throw Error(*std::exchange(callbackError_, std::nullopt));
    }
}

template <class Handler>
void Viewer::guarded(GLFWwindow* window, Handler&& handler) {
    Viewer& viewer = of(window);
    try {
        handler(viewer);
    } catch (const std::exception& error) {
        viewer.callbackError_ = error.what();
    }
}

void Viewer::onMouseButton(GLFWwindow* window, int button, int action, int mods) {
    ImGui_ImplGlfw_MouseButtonCallback(window, button, action, mods);
    guarded(window, [&](Viewer& viewer) {
        if (action == GLFW_RELEASE) {
            viewer.drag_ = DragButton::None;
            return;
        }
        glm::dvec2 cursor;
        glfwGetCursorPos(window, &cursor.x, &cursor.y);
        if (action != GLFW_PRESS || viewer.panelTakes(cursor)) {
            return;
        }
        viewer.lastCursor_ = cursor;
        if (button == GLFW_MOUSE_BUTTON_LEFT) {
            viewer.drag_ = DragButton::Orbit;
            const double now = glfwGetTime();
            if (viewer.lightKeyHeld()) {
                viewer.lastClickTime_ = -1.0;  // a light drag, not half a double click
            } else if (now - viewer.lastClickTime_ < kDoubleClickSeconds &&
                       glm::length(cursor - viewer.lastClickPosition_) < kDoubleClickPixels) {
                viewer.lastClickTime_ = -1.0;
                viewer.pickCentreAt(cursor);
            } else {
                viewer.lastClickTime_ = now;
                viewer.lastClickPosition_ = cursor;
            }
        } else if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) {
            viewer.drag_ = DragButton::Pan;
        }
    });
}

void Viewer::onCursorPosition(GLFWwindow* window, double x, double y) {
    guarded(window, [&](Viewer& viewer) {
        const glm::dvec2 cursor(x, y);
        const glm::dvec2 delta = cursor - viewer.lastCursor_;
        viewer.lastCursor_ = cursor;
        if (viewer.drag_ == DragButton::Orbit) {
            // Decided at every move: pressing or releasing L during a drag switches between
            // turning the light and the view, and the view never moves while L is held.
            if (viewer.lightKeyHeld()) {
                viewer.dragLight(delta.x, delta.y);
            } else if (viewer.navigation_ == Navigation::Fly) {
                viewer.camera_.look(delta.x, delta.y);
            } else {
                viewer.camera_.orbit(delta.x, delta.y);
            }
        } else if (viewer.drag_ == DragButton::Pan) {
            const glm::dvec2 pixels = delta * viewer.context_.windowToFramebufferScale();
            viewer.camera_.pan(pixels.x, pixels.y, viewer.viewportSize().y);
        }
    });
}

void Viewer::onScroll(GLFWwindow* window, double dx, double dy) {
    ImGui_ImplGlfw_ScrollCallback(window, dx, dy);
    guarded(window, [&](Viewer& viewer) {
        glm::dvec2 cursor;
        glfwGetCursorPos(window, &cursor.x, &cursor.y);
        if (!viewer.panelTakes(cursor)) {
            viewer.zoomAt(cursor, dy);
        }
    });
}

void Viewer::onKey(GLFWwindow* window, int key, int scancode, int action, int mods) {
    ImGui_ImplGlfw_KeyCallback(window, key, scancode, action, mods);
    guarded(window, [&](Viewer& viewer) {
        if (action == GLFW_PRESS && !ImGui::GetIO().WantCaptureKeyboard) {
            viewer.handleKey(key);
        }
    });
}

void Viewer::onChar(GLFWwindow* window, unsigned int codepoint) {
    ImGui_ImplGlfw_CharCallback(window, codepoint);
}

void Viewer::onDrop(GLFWwindow* window, int count, const char** paths) {
    guarded(window, [&](Viewer& viewer) {
        if (count > 0) {
            viewer.pendingOpen_ = paths[0];
        }
    });
}

void Viewer::onFocus(GLFWwindow* window, int focused) {
    ImGui_ImplGlfw_WindowFocusCallback(window, focused);
}

void Viewer::onCursorEnter(GLFWwindow* window, int entered) {
    ImGui_ImplGlfw_CursorEnterCallback(window, entered);
}

bool Viewer::panelTakes(const glm::dvec2& cursor) const {
    return ImGui::GetIO().WantCaptureMouse || (showPanel_ && panel_.covers(cursor));
}

void Viewer::handleKey(int key) {
    const glm::ivec2 size = viewportSize();
    switch (key) {
        case GLFW_KEY_ESCAPE:
            glfwSetWindowShouldClose(context_.window(), GLFW_TRUE);
            break;
        case GLFW_KEY_R:
            camera_.reset(size.x, size.y);
            break;
        case GLFW_KEY_F:
            camera_.frameAll(size.x, size.y);
            break;
        case GLFW_KEY_V:
            lookFromSensor();
            break;
        case GLFW_KEY_P:
            pendingScreenshots_.push_back(nextScreenshotPath());
            break;
        case GLFW_KEY_TAB:
            showPanel_ = !showPanel_;
            break;
        case GLFW_KEY_L:
            firstLight();
            break;
        case GLFW_KEY_C:
            navigation_ = navigation_ == Navigation::Orbit ? Navigation::Fly : Navigation::Orbit;
            notify(navigation_ == Navigation::Fly ? "fly: WASD to move, Q/E down/up, drag to look"
                                                  : "orbit: drag to turn around the centre");
            break;
        default:
            break;
    }
}

bool Viewer::lightKeyHeld() const {
    return glfwGetKey(context_.window(), GLFW_KEY_L) == GLFW_PRESS &&
           !ImGui::GetIO().WantCaptureKeyboard;
}

DirectionalLight& Viewer::firstLight() {
    std::vector<DirectionalLight>& lights = settings_.shading.lights;
    if (lights.empty()) {
        lights.push_back({glm::vec3(camera_.defaultLightDirection()), glm::vec3(1.0f)});
        notify("added light 1 from the upper left: hold L and drag to turn it");
    }
    return lights.front();
}

void Viewer::dragLight(double dxPixels, double dyPixels) {
    DirectionalLight& light = firstLight();
    // The drag turns the light in the scene; a light fixed to the view keeps its direction
    // relative to the camera afterwards.
    const glm::dmat4 view = camera_.camera(1, 1).view;
    const glm::dvec3 turned =
        camera_.dragLight(towardsLightInWorld(light, view), dxPixels, dyPixels);
    light.direction =
        glm::vec3(light.space == LightSpace::World ? turned : glm::dmat3(view) * turned);
}

void Viewer::flyWithKeys(double seconds) {
    flying_ = false;
    if (navigation_ != Navigation::Fly || ImGui::GetIO().WantCaptureKeyboard) {
        return;
    }
    GLFWwindow* window = context_.window();
    const auto held = [window](int key) {
        return glfwGetKey(window, key) == GLFW_PRESS ? 1.0 : 0.0;
    };
    const glm::dvec3 direction(held(GLFW_KEY_D) - held(GLFW_KEY_A),
                               held(GLFW_KEY_E) - held(GLFW_KEY_Q),
                               held(GLFW_KEY_S) - held(GLFW_KEY_W));
    if (direction == glm::dvec3(0.0)) {
        return;
    }
    flying_ = true;
    const bool fast = held(GLFW_KEY_LEFT_SHIFT) > 0.0 || held(GLFW_KEY_RIGHT_SHIFT) > 0.0;
    const double speed =
        kFlyRadiiPerSecond * camera_.sceneRadius() * (fast ? kFlyShiftFactor : 1.0);
    camera_.move(direction * speed * std::min(seconds, kMaxFlyStepSeconds));
}

// ---- loading ---------------------------------------------------------------------------------

void Viewer::startLoading(const std::string& source, bool reopening) {
    // Replacing a running job cancels it (its destructor waits for the thread); so does
    // dropping a view's, whose nodes belong to the scan on screen.
    // A whole scan's completion goes on: the load may fail and leave its scan on screen (show()
    // stops it before the scan goes).
    loading_ = std::make_unique<ScanLoadJob>(source, settings_.streaming);
    refining_.reset();
    status_.streamingView = false;
    reopening_ = reopening;
    openedLod_ = settings_.streaming.lod;
    status_.loadingSource = source;
    // The first scan opens with the program (GLFW's clock starts at its initialisation).
    openedAt_ = initialScanShown_ ? glfwGetTime() : 0.0;
    status_.firstPictureSeconds = 0.0;
    status_.viewCompleteSeconds = 0.0;
    viewNodesShown_ = false;
}

void Viewer::reopenForLevelsOfDetail() {
    // Streamed or whole is decided when a scan opens: the panel's, a script's or a loaded
    // file's change opens it again, where that changes which it is. A streamed scan stays
    // streamed under `auto` and `on`; a scan `auto` loaded whole is not COPC or EPT, and
    // stays whole under `off` (`on` opens it again, to refuse it).
    const lod::LodMode wanted = settings_.streaming.lod;
    const bool same = streamed_ ? wanted != lod::LodMode::Off
                                : openedLod_ != lod::LodMode::Off && wanted == lod::LodMode::Off;
    if (same) {
        openedLod_ = shownLod_ = wanted;
        return;
    }
    startLoading(status_.scanSource, true);
}

void Viewer::warmUpRenderer() {
    PointCloud placeholder;
    placeholder.positions = {glm::vec3(0.0f), glm::vec3(1.0f)};
    placeholder.colors = {Rgba8{128, 128, 128, 255}, Rgba8{128, 128, 128, 255}};
    placeholder.bounds.add(glm::dvec3(0.0));
    placeholder.bounds.add(glm::dvec3(1.0));
    const glm::ivec2 size = viewportSize();
    try {
        auto renderer = std::make_unique<Renderer>(context_, placeholder, PointSpacing{0.1, {}});
        renderer->render(orbitCamera(placeholder.bounds, OrbitView{}, std::max(size.x, 1),
                                     std::max(size.y, 1), ViewerCamera::kFovyDegrees),
                         appliedSettings());
        warmRenderer_ = std::move(renderer);
    } catch (const Error&) {
        // Only time is lost: the scan's own first frame compiles and reports what failed.
    }
}

void Viewer::recordOpeningTimes() {
    if (!renderer_ || !renderedImage_ || loading_) {
        return;
    }
    const double seconds = glfwGetTime() - openedAt_;
    if (status_.firstPictureSeconds == 0.0) {
        status_.firstPictureSeconds = seconds;
    }
    if ((streamed_ ? viewNodesShown_ && !arriving_ : !completing_) &&
        status_.viewCompleteSeconds == 0.0) {
        status_.viewCompleteSeconds = seconds;
    }
}

bool Viewer::fading() const {
    return renderer_ && renderedImage_ &&
           crossFade_.active(renderer_->resources().texture("image"), glfwGetTime());
}

bool Viewer::levelsOfDetailChanged() const {
    return initialScanShown_ && settings_.streaming.lod != openedLod_;
}

bool Viewer::awaitingScan() const {
    return unattended_ && (loading_ || completing_ || arriving_ || levelsOfDetailChanged() ||
                           (streamed_ && (refining_ || dueRefinement())));
}

void Viewer::fadeFromScreen() {
    // A fade still running starts over from what it shows now, not from its older picture.
    const Texture& image = renderer_->resources().texture("image");
    crossFade_.start(crossFade_.active(image, glfwGetTime()) ? crossFade_.blended() : image);
}

void Viewer::finishCompleting() {
    if (!completing_ || !completing_->finished()) {
        return;
    }
    const std::unique_ptr<BackgroundJob<std::optional<CompletedSpacing>>> job =
        std::move(completing_);
    status_.completingSpacing = false;
    try {
        std::optional<CompletedSpacing> completed = job->take();
        // Evenly spaced and too large for normals: nothing to add to the picture.
        if (!completed || (completed->spacing.local.empty() && completed->packed.normals.empty())) {
            return;
        }
        // Interactive: the provisional picture fades into the completed one.
        if (!unattended_ && renderedImage_) {
            fadeFromScreen();
        }
        renderer_->replaceCloud(*scan_, completed->spacing, PointMemory::Borrow,
                                std::move(completed->packed));
        status_.spacing = renderer_->spacing();
        renderedCamera_.reset();
        renderedImage_ = false;
    } catch (const Error& error) {
        fail(error.what());
    }
}

void Viewer::finishLoading() {
    if (!loading_) {
        return;
    }
    status_.loadingProgress = loading_->progress();
    if (!loading_->finished()) {
        return;
    }
    const std::unique_ptr<ScanLoadJob> job = std::move(loading_);
    status_.loadingSource.reset();
    try {
        show(job->take(), true);
    } catch (const Error& error) {
        if (!initialScanShown_) {
            throw;  // nothing to show: the command fails as `subscan render` would
        }
        // The scan on screen stays, and so does the mode it was opened with.
        settings_.streaming.lod = openedLod_ = shownLod_;
        fail(error.what());
    }
}

void Viewer::show(PreparedScan prepared, bool newScan) {
    for (const std::string& warning : prepared.scan.warnings) {
        fmt::print(stderr, "subscan: warning: {}: {}\n", prepared.source, warning);
    }
    Arrival arrival;
    arrival.newScan = newScan;
    arrival.up = !newScan      ? scanUp_
                 : options_.up ? *options_.up
                               : upAxisForScan("auto", prepared.scan.format, prepared.scan.cloud,
                                               prepared.scan.grid);
    // Before the cloud moves on: an organised grid's camera is fitted to its points.
    arrival.look = newScan ? sensorLook(prepared.scan, arrival.up) : sensorLook_;
    // A scan opened again (another streaming.lod) keeps the view and the colouring.
    const bool keepView = !newScan || reopening_;
    arrival.coloring = keepView ? status_.coloring : options_.coloring;
    if (prepared.coloredBy == std::pair(arrival.coloring, arrival.up)) {
        arrival.fileColors = std::move(prepared.scan.cloud.colors);
        prepared.scan.cloud.colors = std::move(prepared.shownColors);
    } else {
        arrival.fileColors = prepared.scan.cloud.colors;
        prepared.scan.cloud.colors = pointColors(prepared.scan.cloud, arrival.coloring, arrival.up);
    }
    // The renderer reads the points where they are (no copy where the driver allows): the
    // scan stays at its address until the renderer reads another.
    arrival.scan = std::make_unique<PointCloud>(std::move(prepared.scan.cloud));
    arrival.prepared = std::move(prepared);
    // Another set of a streamed scan's nodes goes to the GPU a frame's worth at a time while
    // the nodes before them stay on screen (continueArrival); it replaces a set still on its
    // way. A new scan goes on screen at once: there is nothing else to show.
    if (!newScan && renderer_) {
        arriving_.reset();
        arrival.upload = renderer_->startUpload(*arrival.scan, PointMemory::Borrow,
                                                std::move(arrival.prepared.packed));
        arriving_ = std::make_unique<Arrival>(std::move(arrival));
        status_.uploadingBytes = arriving_->upload->bytesLeft();
        return;
    }
    putOnScreen(std::move(arrival));
}

void Viewer::continueArrival() {
    if (!arriving_) {
        return;
    }
    ++uploadFrames_;
    try {
        const std::size_t bytes = settings_.streaming.uploadMegabytesPerFrame << 20;
        if (!arriving_->upload->advance(bytes)) {
            status_.uploadingBytes = arriving_->upload->bytesLeft();
            return;
        }
        status_.uploadingBytes = 0;
        putOnScreen(std::move(*std::exchange(arriving_, nullptr)));
    } catch (const Error& error) {
        dropArrival();
        fail(error.what());
    }
}

void Viewer::dropArrival() {
    arriving_.reset();
    status_.uploadingBytes = 0;
    // The view the dropped nodes were for loads again.
    refinedCamera_.reset();
}

void Viewer::putOnScreen(Arrival arrival) {
    PreparedScan& prepared = arrival.prepared;
    const bool newScan = arrival.newScan;
    const bool provisional = prepared.provisional;
    // Interactive: what was on screen fades into the new nodes' picture (unattended runs show
    // what `render` would at once).
    if (!newScan && !unattended_ && renderer_ && renderedImage_) {
        fadeFromScreen();
    } else {
        crossFade_.stop();
    }
    // One renderer for every scan and view (its passes compiled and images made once); a
    // failure to take the new points keeps the old ones on screen, where they are.
    std::unique_ptr<PointCloud> scan = std::move(arrival.scan);
    if (!renderer_) {
        // The first scan: the warmed-up renderer where there is one (a failure here ends the
        // program, as nothing is on screen).
        renderer_ = std::move(warmRenderer_);
    }
    if (renderer_ && arrival.upload) {
        renderer_->replaceCloud(*scan, prepared.spacing, std::move(*arrival.upload));
    } else if (renderer_) {
        renderer_->replaceCloud(*scan, prepared.spacing, PointMemory::Borrow,
                                std::move(prepared.packed));
    } else {
        renderer_ =
            std::make_unique<Renderer>(context_, *scan, prepared.spacing, 0, PointMemory::Borrow);
    }
    // A whole scan's completion reads the scan on screen, which this replaces (where the
    // renderer took the new one: else the old stays, and so does its completion), and the old
    // scan's nodes on their way to it go too.
    completing_.reset();
    if (newScan) {
        dropArrival();
    }
    scan_ = std::move(scan);
    scanColors_ = std::move(arrival.fileColors);
    // A streamed scan's provisional nodes stay only until its view's come (refineStreamedView).
    shownProvisional_ = provisional;
    status_.completingSpacing = provisional && !prepared.streamed;
    if (status_.completingSpacing) {
        completing_ = std::make_unique<BackgroundJob<std::optional<CompletedSpacing>>>(
            prepared.source, [shown = scan_.get(), sample = std::move(prepared.sample)](
                                 const std::function<bool()>& cancelled) {
                return completeSpacing(*shown, sample, cancelled);
            });
    }
    scanUp_ = arrival.up;
    sensorLook_ = std::move(arrival.look);
    streamed_ = std::move(prepared.streamed);
    streamedNodes_ = std::move(prepared.nodes);
    status_.coloring = arrival.coloring;
    const PointCloud& cloud = *scan_;
    status_.points = cloud.size();
    status_.spacing = renderer_->spacing();
    status_.streamedNodes = streamedNodes_.size();
    status_.streamedNodesInAll = streamed_ ? streamed_->nodes().size() : 0;
    status_.streamedPointsInAll = streamed_ ? streamed_->info().points : 0;
    status_.nodeCacheBytes = streamed_ ? streamed_->usage().bytes : 0;
    status_.nodeCacheBudgetBytes = streamed_ ? streamed_->byteBudget() : 0;
    renderedCamera_.reset();
    renderedImage_ = false;
    if (!newScan) {
        return;
    }
    refining_.reset();
    refinedCamera_.reset();
    stillCamera_.reset();
    bounds_ = cloud.bounds;
    status_.scanSource = prepared.source;
    status_.scanFormat =
        prepared.scan.formatDetail.empty() ? prepared.scan.format : prepared.scan.formatDetail;
    status_.loadMilliseconds = prepared.scan.loadMilliseconds;
    if (!reopening_) {
        const glm::ivec2 size = viewportSize();
        camera_ = ViewerCamera(bounds_, arrival.up, std::max(size.x, 1), std::max(size.y, 1),
                               framingBounds(cloud));
    }
    shownLod_ = openedLod_;
    glfwSetWindowTitle(context_.window(), ("subscan: " + prepared.source).c_str());
    initialScanShown_ = true;
}

std::optional<Camera> Viewer::dueRefinement() const {
    if (!streamed_ || !renderer_ || loading_ || refining_) {
        return std::nullopt;
    }
    const glm::ivec2 size = viewportSize();
    const Camera camera = camera_.camera(std::max(size.x, 1), std::max(size.y, 1));
    if (refinedCamera_ && sameCamera(*refinedCamera_, camera) &&
        refinedBudget_ == settings_.streaming.pointBudget) {
        return std::nullopt;
    }
    return camera;
}

void Viewer::refineStreamedView() {
    if (refining_) {
        if (!refining_->finished()) {
            // Interactive: the view's first nodes while the rest load (unattended runs wait
            // for the whole view, which is what `render` draws).
            if (!unattended_) {
                if (std::optional<PreparedScan> partial = refining_->takePartial()) {
                    try {
                        show(std::move(*partial), false);
                    } catch (const Error& error) {
                        fail(error.what());
                    }
                }
            }
            return;
        }
        const std::unique_ptr<StreamedViewJob> job = std::move(refining_);
        status_.streamingView = false;
        try {
            if (std::optional<PreparedScan> prepared = job->take()) {
                show(std::move(*prepared), false);
            }
            viewNodesShown_ = true;
        } catch (const Error& error) {
            fail(error.what());
        }
    }
    const std::optional<Camera> camera = dueRefinement();
    if (!camera) {
        return;
    }
    // Interactive: once the camera has rested a moment, so that an orbit does not start a
    // load at every step; the view the scan opens with at once. Unattended (scripts, tests):
    // at once (awaitingScan).
    const double now = glfwGetTime();
    if (!stillCamera_ || !sameCamera(*stillCamera_, *camera)) {
        stillCamera_ = camera;
        stillSince_ = now;
    }
    if (!unattended_ && refinedCamera_ && now - stillSince_ < kRefineAfterRestSeconds) {
        return;
    }
    refinedCamera_ = camera;
    refinedBudget_ = settings_.streaming.pointBudget;
    const std::uint64_t budget =
        lod::pointBudgetFor(settings_.streaming.pointBudget, context_.capabilities().software);
    // Nodes shown provisionally are loaded again, with their spacing, where the view selects
    // just them. Nodes on their way to the GPU count as shown: they will be.
    const bool provisional = arriving_ ? arriving_->prepared.provisional : shownProvisional_;
    const std::vector<std::size_t>& shown = arriving_ ? arriving_->prepared.nodes : streamedNodes_;
    refining_ = std::make_unique<StreamedViewJob>(streamed_, status_.scanSource, *camera, budget,
                                                  provisional ? std::vector<std::size_t>{} : shown,
                                                  std::pair(status_.coloring, scanUp_),
                                                  partialViewPoints(budget));
    status_.streamingView = true;
}

// ---- script ----------------------------------------------------------------------------------

void Viewer::runScript() {
    const std::vector<ScriptAction>& actions = options_.script;
    while (nextAction_ < actions.size() && actions[nextAction_].frame <= frame_) {
        runScriptCommand(actions[nextAction_].command);
        ++nextAction_;
    }
}

void Viewer::runScriptCommand(const ScriptCommand& command) {
    const glm::ivec2 size = viewportSize();
    std::visit(Overloaded{
                   [&](const script::Orbit& orbit) { camera_.orbit(orbit.dx, orbit.dy); },
                   [&](const script::Pan& pan) {
                       const glm::dvec2 pixels =
                           glm::dvec2(pan.dx, pan.dy) * context_.windowToFramebufferScale();
                       camera_.pan(pixels.x, pixels.y, size.y);
                   },
                   [&](const script::Zoom& zoom) {
                       // What the user would have seen under the cursor: the current view.
                       renderIfNeeded();
                       zoomAt(zoom.at.value_or(windowCentre()), zoom.amount);
                   },
                   [&](const script::Pick& pick) {
                       renderIfNeeded();
                       pickCentreAt(pick.at.value_or(windowCentre()));
                   },
                   [&](const script::Reset&) { camera_.reset(size.x, size.y); },
                   [&](const script::FrameAll&) { camera_.frameAll(size.x, size.y); },
                   [&](const script::Sensor&) { lookFromSensor(); },
                   [&](const script::Color& color) { applyColoring(color.coloring); },
                   [&](const script::Resize& resize) { resizeWindow(resize.width, resize.height); },
                   [&](const script::Screenshot& screenshot) {
                       pendingScreenshots_.push_back(screenshot.path);
                   },
                   [&](const script::SetMode& mode) {
                       settings_.raster.mode = mode.mode;
                       if (!stageAvailable(settings_.raster.stage, mode.mode)) {
                           settings_.raster.stage = Stage::Final;
                       }
                   },
                   [&](const script::ShowPanel& panel) { showPanel_ = panel.show; },
                   [&](const script::Light& light) { dragLight(light.dx, light.dy); },
                   [&](const script::Settings& change) { changeSettings(change.patch); },
                   [&](const script::Exit&) { exitRequested_ = true; },
               },
               command);
}

void Viewer::changeSettings(const std::string& patch) {
    try {
        nlohmann::json merged = settings_;
        merged.merge_patch(nlohmann::json::parse(patch));
        settings_ = merged.get<RenderSettings>();
    } catch (const Error& error) {
        fail(error.what());
    } catch (const nlohmann::json::exception& error) {
        fail(fmt::format("the script's settings do not fit the settings file's form: {}",
                         error.what()));
    }
}

void Viewer::applyColoring(Coloring coloring) {
    if (!renderer_) {
        return;
    }
    // Nodes on their way are coloured the old way: they load again, coloured the new.
    if (arriving_) {
        dropArrival();
    }
    // The renderer may read the shown colours in place: they stay alive and unchanged (moved
    // out, not overwritten) until it has a copy of the new ones.
    const std::vector<Rgba8> shown = std::exchange(scan_->colors, scanColors_);
    std::vector<Rgba8> colors = pointColors(*scan_, coloring, scanUp_);
    renderer_->setColors(colors);
    scan_->colors = std::move(colors);
    status_.coloring = coloring;
    renderedCamera_.reset();
    notify("points coloured by " + toString(coloring));
}

void Viewer::lookFromSensor() {
    if (sensorLook_) {
        camera_.lookFrom(sensorLook_->first, sensorLook_->second);
        notify("the view from the scan's sensor");
    } else {
        notify("this scan records no sensor position");
    }
}

void Viewer::resizeWindow(int width, int height) {
    GLFWwindow* window = context_.window();
    glfwSetWindowSize(window, width, height);
    const double deadline = glfwGetTime() + kResizeTimeoutSeconds;
    for (;;) {
        int currentWidth = 0, currentHeight = 0;
        glfwGetWindowSize(window, &currentWidth, &currentHeight);
        if (currentWidth == width && currentHeight == height) {
            return;
        }
        if (glfwGetTime() > deadline) {
            fail(fmt::format("the window system kept the window at {}x{} instead of {}x{}",
                             currentWidth, currentHeight, width, height));
            return;
        }
        glfwWaitEventsTimeout(0.01);
    }
}

// ---- drawing ---------------------------------------------------------------------------------

RenderSettings Viewer::appliedSettings() const {
    RenderSettings settings = settings_;
    settings.scattering = scattering_.settings();
    return settings;
}

void Viewer::offerSettings() {
    const std::string refusedBefore = scattering_.refusal();
    if (const std::optional<std::string> refusal = scattering_.offer(settings_.scattering)) {
        fail(*refusal);
    } else if (!refusedBefore.empty() && scattering_.refusal().empty() && status_.messageIsError &&
               status_.message == refusedBefore) {
        status_.message.clear();  // mended: the error no longer holds
    }
    status_.scatteringRefusal = scattering_.refusal();
}

bool Viewer::frameIsStale() const {
    const glm::ivec2 size = viewportSize();
    if (!renderer_ || size.x < 1 || size.y < 1) {
        return false;
    }
    const RenderSettings settings = appliedSettings();
    const bool changed = !renderedCamera_ ||
                         !sameCamera(*renderedCamera_, camera_.camera(size.x, size.y)) ||
                         nlohmann::json(settings).dump() != renderedSettings_;
    // While a view's nodes load or upload, or a scan's local spacing and normals, the temporal
    // filter does not refine the picture at rest: they replace it in a moment, and on llvmpipe its
    // frames took the cores their work needs. Nor during a cross-fade: on llvmpipe a filtered
    // frame took 0.25 s at 1280x720, which left two frames of a 0.3 s fade; the fade's own
    // frames are a blend and a copy.
    return redrawEveryFrame_ || changed ||
           (filtersTemporally(settings) && renderedImage_ && !refining_ && !arriving_ &&
            !completing_ && !fading() &&
            framesAtRest_ + 1 < kTemporalRestFrames);  // a failed frame is not retried
}

void Viewer::renderIfNeeded() {
    offerSettings();  // a script's change since the panel last offered them
    if (!frameIsStale()) {
        return;
    }
    const glm::ivec2 size = viewportSize();
    const Camera camera = camera_.camera(size.x, size.y);
    const RenderSettings settings = appliedSettings();
    const std::string settingsJson = nlohmann::json(settings).dump();
    const bool atRest = renderedCamera_ && sameCamera(*renderedCamera_, camera) &&
                        settingsJson == renderedSettings_;
    framesAtRest_ = atRest ? framesAtRest_ + 1 : 0;
    // Recorded before rendering: a frame that fails is not retried until something changes.
    renderedCamera_ = camera;
    renderedSettings_ = settingsJson;
    renderedMode_ = settings.raster.mode;
    renderedImage_ = false;
    try {
        const FrameResult frame = renderer_->render(camera, settings);
        status_.passes = frame.passes;
        status_.imageWidth = size.x;
        status_.imageHeight = size.y;
        status_.divisor = frame.divisor;
        renderedImage_ = true;
    } catch (const Error& error) {
        fail(error.what());
    }
}

void Viewer::drawFrame() {
    const glm::ivec2 size = viewportSize();
    if (size.x < 1 || size.y < 1) {
        return;  // minimised: nothing to draw into
    }
    renderIfNeeded();
    if (renderer_ && renderedImage_) {
        const Texture& image = renderer_->resources().texture("image");
        const double now = glfwGetTime();
        if (crossFade_.active(image, now)) {
            context_.presentImage(crossFade_.blend(image, now));
        } else {
            crossFade_.stop();  // over, or the window changed size
            context_.presentImage(image);
        }
    } else {
        context_.clearWindow(settings_.raster.backgroundSrgb);
    }
    drawPanel();
}

void Viewer::drawPanel() {
    imgui_.beginFrame();
    status_.windowFps = ImGui::GetIO().Framerate;
    PanelRequests requests;
    if (showPanel_) {
        status_.newLightDirection = glm::vec3(camera_.defaultLightDirection());
        requests = panel_.draw(settings_, navigation_, redrawEveryFrame_, status_);
    }
    imgui_.endFrame();

    const glm::ivec2 size = viewportSize();
    if (requests.screenshot) {
        pendingScreenshots_.push_back(nextScreenshotPath());
    }
    if (requests.resetView) {
        camera_.reset(size.x, size.y);
    }
    if (requests.frameAll) {
        camera_.frameAll(size.x, size.y);
    }
    if (requests.openScan) {
        pendingOpen_ = requests.openScan;
    }
    try {
        if (requests.coloring) {
            applyColoring(*requests.coloring);
        }
        if (requests.saveSettings) {
            // A file of refused settings would not load again; the panel's are the ones the
            // user means, so they are not swapped for the applied ones either.
            if (!scattering_.refusal().empty()) {
                throw Error("the settings were not saved: " + scattering_.refusal());
            }
            writeSettingsFile(*requests.saveSettings, settings_);
            notify("saved the settings to " + *requests.saveSettings);
        }
        if (requests.loadSettings) {
            settings_ = readSettingsFile(*requests.loadSettings, viewerDefaultSettings());
            notify("loaded the settings from " + *requests.loadSettings);
        }
    } catch (const Error& error) {
        fail(error.what());
    }
    // The panel's edits of this frame: a refusal shows at once, a change renders at once.
    offerSettings();
}

void Viewer::writeScreenshot(const std::filesystem::path& path) {
    const glm::ivec2 size = viewportSize();
    const Camera camera = renderedCamera_ ? *renderedCamera_ : camera_.camera(size.x, size.y);
    try {
        writePng(path, context_.readBackBuffer());
        writeCameraFile(sidecarPath(path, ".camera.json"), camera);
        // What the picture shows.
        writeSettingsFile(sidecarPath(path, ".settings.json"), appliedSettings());
        notify("wrote " + path.string());
    } catch (const Error& error) {
        fail(error.what());
    }
}

std::filesystem::path Viewer::nextScreenshotPath() const {
    for (int number = 1;; ++number) {
        std::filesystem::path path = fmt::format("subscan-screenshot-{:03}.png", number);
        std::error_code ignored;
        if (!std::filesystem::exists(path, ignored) &&
            std::find(pendingScreenshots_.begin(), pendingScreenshots_.end(), path) ==
                pendingScreenshots_.end()) {
            return path;
        }
    }
}

// ---- picking ---------------------------------------------------------------------------------

std::optional<glm::dvec3> Viewer::surfacePointAt(const glm::dvec2& windowPosition) const {
    if (!renderer_ || !renderedCamera_ || !renderedImage_) {
        return std::nullopt;
    }
    const FrameResources& resources = renderer_->resources();
    const char* name = reconstructsSurface(renderedMode_) && resources.has("surfaceDepth")
                           ? "surfaceDepth"
                           : "depth";
    if (!resources.has(name)) {
        return std::nullopt;
    }
    const Texture& depth = resources.texture(name);
    // The depth is the pipeline's, at reduced resolution when the frame was.
    const Camera& pipeline = renderer_->pipelineCamera();
    const glm::dvec2 pixel =
        reducedPosition(*renderedCamera_, pipeline, renderer_->pipelineDivisor(),
                        windowPosition * context_.windowToFramebufferScale());
    const int x = static_cast<int>(std::floor(pixel.x));
    const int y = static_cast<int>(std::floor(pixel.y));
    if (x < 0 || y < 0 || x >= depth.width() || y >= depth.height()) {
        return std::nullopt;
    }
    const int x0 = std::max(x - kPickRadiusPixels, 0);
    const int y0 = std::max(y - kPickRadiusPixels, 0);
    const int x1 = std::min(x + kPickRadiusPixels, depth.width() - 1);
    const int y1 = std::min(y + kPickRadiusPixels, depth.height() - 1);
    const int blockWidth = x1 - x0 + 1;
    const int blockHeight = y1 - y0 + 1;
    std::vector<float> block(static_cast<std::size_t>(blockWidth * blockHeight));
    // Texel rows run from the top of the image, as the pipeline writes them.
    glGetTextureSubImage(depth.id(), 0, x0, y0, 0, blockWidth, blockHeight, 1, GL_RED, GL_FLOAT,
                         static_cast<GLsizei>(block.size() * sizeof(float)), block.data());

    // The nearest texel with a surface; of equally near ones the frontmost.
    std::optional<glm::dvec2> best;
    double bestDepth = 0.0;
    double bestDistance = std::numeric_limits<double>::infinity();
    for (int row = 0; row < blockHeight; ++row) {
        for (int column = 0; column < blockWidth; ++column) {
            const double value = block[static_cast<std::size_t>(row * blockWidth + column)];
            if (!(value > 0.0 && std::isfinite(value))) {
                continue;
            }
            const glm::dvec2 centre(x0 + column + 0.5, y0 + row + 0.5);
            const double distance = glm::length(centre - pixel);
            if (distance < bestDistance || (distance == bestDistance && value < bestDepth)) {
                best = centre;
                bestDepth = value;
                bestDistance = distance;
            }
        }
    }
    if (!best) {
        return std::nullopt;
    }
    return ViewerCamera::unproject(pipeline, *best, bestDepth);
}

void Viewer::zoomAt(const glm::dvec2& windowPosition, double steps) {
    const glm::ivec2 size = viewportSize();
    const glm::dvec3 target =
        surfacePointAt(windowPosition)
            .value_or(camera_.pointAtCentreDepth(
                windowPosition * context_.windowToFramebufferScale(), size.x, size.y));
    camera_.zoomTowards(steps, target);
}

void Viewer::pickCentreAt(const glm::dvec2& windowPosition) {
    if (const std::optional<glm::dvec3> point = surfacePointAt(windowPosition)) {
        camera_.setCentre(*point);
    } else {
        notify("nothing under the cursor to orbit around");
    }
}

glm::dvec2 Viewer::windowCentre() const {
    int width = 0, height = 0;
    glfwGetWindowSize(context_.window(), &width, &height);
    return glm::dvec2(width, height) * 0.5;
}

glm::ivec2 Viewer::viewportSize() const {
    return context_.framebufferSize();
}

// ---- messages --------------------------------------------------------------------------------

void Viewer::notify(std::string message) {
    fmt::print(stderr, "subscan: {}\n", message);
    status_.message = std::move(message);
    status_.messageIsError = false;
}

void Viewer::fail(std::string message) {
    if (unattended_) {
        throw Error(message);
    }
    fmt::print(stderr, "subscan: {}\n", message);
    status_.message = std::move(message);
    status_.messageIsError = true;
}

}  // namespace subscan::viewer
