#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "app/viewer/CrossFade.h"
#include "app/viewer/ImGuiSession.h"
#include "app/viewer/ScanLoadJob.h"
#include "app/viewer/StreamedViewJob.h"
#include "app/viewer/ViewerCamera.h"
#include "app/viewer/ViewerPanel.h"
#include "app/viewer/ViewerScript.h"
#include "core/Camera.h"
#include "core/Coloring.h"
#include "gpu/GlfwContext.h"
#include "render/RenderSettings.h"

struct GLFWwindow;

namespace subscan {
class Renderer;
}

namespace subscan::viewer {

/// The viewer's defaults: RenderSettings' own with the temporal filter on, so orbiting is steady
/// and a camera at rest refines to an anti-aliased picture.
RenderSettings viewerDefaultSettings();

struct ViewerOptions {
    std::string source;  // a scan file or synthetic:NAME
    int width = 1280;    // window size
    int height = 800;
    RenderSettings settings = viewerDefaultSettings();
    std::optional<UpAxis> up;  // default: upAxisForScan's auto
    Coloring coloring = Coloring::Auto;
    std::vector<ScriptAction> script;
    std::filesystem::path screenshotAtExit;  // empty: none
    std::optional<int> exitAfterFrames;      // frames that show the scan
    bool showPanel = true;
};

/// `subscan view`: a window showing the frame pipeline's image of a scan, live, with a camera
/// driven by mouse and keys (ViewerCamera), the ImGui panel (ViewerPanel) over it, scans loaded
/// off the render thread (ScanLoadJob) and scripted input for unattended runs (ViewerScript).
/// The pipeline renders only when the camera, the settings or the window size changed, or while
/// the temporal filter refines a camera at rest.
class Viewer {
  public:
    /// Opens the window; throws subscan::Error when there is no display or no OpenGL 4.5.
    explicit Viewer(ViewerOptions options);
    ~Viewer();
    Viewer(const Viewer&) = delete;
    Viewer& operator=(const Viewer&) = delete;

    /// Runs until the window is closed, Esc, the script's exit or --exit-after-frames. Throws
    /// subscan::Error when the scan given on the command line cannot be shown, and, in
    /// unattended runs (a script or a frame limit), for any error a user would otherwise see
    /// in the panel.
    int run();

  private:
    enum class DragButton { None, Orbit, Pan };

    // GLFW callbacks: reach the viewer through the window's user pointer and forward the event
    // to ImGui, which may take it.
    static Viewer& of(GLFWwindow* window);
    /// Runs `handler(viewer)`; an exception is kept for waitForEvents to throw, since it must
    /// not unwind through GLFW's C code.
    template <class Handler>
    static void guarded(GLFWwindow* window, Handler&& handler);
    static void onMouseButton(GLFWwindow* window, int button, int action, int mods);
    static void onCursorPosition(GLFWwindow* window, double x, double y);
    static void onScroll(GLFWwindow* window, double dx, double dy);
    static void onKey(GLFWwindow* window, int key, int scancode, int action, int mods);
    static void onChar(GLFWwindow* window, unsigned int codepoint);
    static void onDrop(GLFWwindow* window, int count, const char** paths);
    static void onFocus(GLFWwindow* window, int focused);
    static void onCursorEnter(GLFWwindow* window, int entered);
    void installCallbacks();
    void handleKey(int key);
    /// `L` is held (and not typed into the panel): a left drag turns the light.
    bool lightKeyHeld() const;
    /// The first directional light, added from the upper left of the view when there is none.
    DirectionalLight& firstLight();
    /// A left drag of (dx, dy) window pixels with `L` held (ViewerCamera::dragLight).
    void dragLight(double dxPixels, double dyPixels);
    /// The mouse at `cursor` belongs to the panel (or one of its popups), not to the camera.
    bool panelTakes(const glm::dvec2& cursor) const;

    void waitForEvents();
    /// `reopening`: the scan on screen opens again (another streaming.lod), keeping its view
    /// and colouring.
    void startLoading(const std::string& source, bool reopening = false);
    /// streaming.lod differs from the one the scan on screen was opened with.
    bool levelsOfDetailChanged() const;
    /// Opens the scan again where streaming.lod changed which it is, streamed or whole.
    void reopenForLevelsOfDetail();
    /// While the first scan loads on its own thread: a renderer of a placeholder renders one
    /// frame that is not shown, so that its passes are compiled and its images made by the
    /// time the scan comes (show() gives it the scan). On llvmpipe the first frame of a new
    /// renderer took 0.64 s at 1280x720.
    void warmUpRenderer();
    void finishLoading();
    /// Hands the renderer a whole scan's completed spacing and normals once they are estimated.
    void finishCompleting();
    /// Starts the cross-fade from the picture on screen (interactive hand-overs).
    void fadeFromScreen();
    /// A prepared scan on its way to the screen: its points (where the renderer reads them),
    /// their own colours and how show() coloured them.
    struct Arrival {
        PreparedScan prepared;  // its cloud moved to `scan`
        std::unique_ptr<PointCloud> scan;
        std::vector<Rgba8> fileColors;
        Coloring coloring = Coloring::Auto;
        UpAxis up = UpAxis::Y;
        std::optional<std::pair<glm::dvec3, glm::dvec3>> look;  // sensorLook_'s
        bool newScan = false;
        /// Another set of a streamed scan's nodes: their upload (reads `scan`, declared before
        /// it so that it goes last).
        std::optional<GpuPointCloudUpload> upload;
    };
    /// Puts a prepared scan on screen: a new one (`newScan`: its colouring, sensor and camera
    /// start afresh) at once, or another set of the streamed scan's nodes (the view stays) once
    /// continueArrival() has uploaded it.
    void show(PreparedScan prepared, bool newScan);
    /// Uploads streaming.upload_megabytes_per_frame more of the nodes on their way, and puts
    /// them on screen once all are on the GPU.
    void continueArrival();
    /// Forgets the nodes on their way; their view loads again.
    void dropArrival();
    void putOnScreen(Arrival arrival);
    /// An unattended run (script, frame limit) is waiting for a scan that opens again, for a
    /// streamed view's nodes or for a whole scan's local spacing and normals: its frames show
    /// what is there meanwhile but do not count, so every counted frame shows what `subscan
    /// render` would.
    bool awaitingScan() const;
    /// A cross-fade to a streamed view's new nodes, or to a whole scan's complete picture, is
    /// under way: frames are drawn until it ends.
    bool fading() const;
    /// After a frame was shown: when the scan's first picture came, and its view's nodes (a
    /// whole scan: its local spacing and normals).
    void recordOpeningTimes();
    /// The camera whose nodes a streamed scan should load next: the view, where it is not the
    /// one last refined for and no load runs.
    std::optional<Camera> dueRefinement() const;
    /// A streamed scan: takes a finished StreamedViewJob's nodes, and starts one for the view
    /// once the camera rests.
    void refineStreamedView();
    void runScript();
    void runScriptCommand(const ScriptCommand& command);
    /// Merges `patch` (JSON text in the settings file's form) into the settings, checked as a
    /// settings file is; an impossible result is an error and changes nothing.
    void changeSettings(const std::string& patch);
    void resizeWindow(int width, int height);
    /// `V`: the camera to where the scan was taken, or a note that it records no such place.
    void lookFromSensor();
    void flyWithKeys(double seconds);

    /// The panel's settings with the scattering settings in effect (AppliedScattering): what
    /// the pipeline renders.
    RenderSettings appliedSettings() const;
    /// Offers the panel's scattering settings to scattering_; a refusal is an error (once).
    void offerSettings();
    /// The camera, the applied settings or the window size differ from what the last pipeline
    /// frame showed (or every frame is to be rendered).
    bool frameIsStale() const;
    /// Renders the pipeline for the current camera and settings when the frame is stale.
    void renderIfNeeded();
    /// Scene (or background) and panel into the back buffer.
    void drawFrame();
    void drawPanel();
    void writeScreenshot(const std::filesystem::path& path);
    std::filesystem::path nextScreenshotPath() const;

    /// The scene point under a window position in the last rendered frame (reconstructed depth
    /// in the surface modes, the points' depth otherwise), searched a few pixels around it.
    std::optional<glm::dvec3> surfacePointAt(const glm::dvec2& windowPosition) const;
    void zoomAt(const glm::dvec2& windowPosition, double steps);
    void pickCentreAt(const glm::dvec2& windowPosition);
    glm::dvec2 windowCentre() const;
    glm::ivec2 viewportSize() const;

    /// A notice for the panel (and stderr).
    void notify(std::string message);
    /// An error: thrown in unattended runs, shown in the panel otherwise.
    void fail(std::string message);

    ViewerOptions options_;
    bool unattended_;
    GlfwContext context_;
    ImGuiSession imgui_;
    CrossFade crossFade_;  // from a picture to the next nodes' or the complete scan's
    ViewerPanel panel_;
    RenderSettings settings_;  // as the panel shows them
    AppliedScattering scattering_;
    bool showPanel_;
    bool redrawEveryFrame_ = false;
    Navigation navigation_ = Navigation::Orbit;

    /// Colours the scan's points by `coloring` (the panel's choice; the file's own colours
    /// stay in scanColors_) and uploads the new colours.
    void applyColoring(Coloring coloring);

    // The scan on screen: its points as loaded, their own colours and the up axis (what a new
    // colouring is made from). The renderer reads the points in place: declared before it, so
    // that it goes first.
    std::unique_ptr<PointCloud> scan_;
    std::vector<Rgba8> scanColors_;
    UpAxis scanUp_ = UpAxis::Y;
    std::unique_ptr<Renderer> renderer_;
    std::unique_ptr<Renderer> warmRenderer_;  // warmUpRenderer()'s, until the first scan comes
    PanelStatus status_;
    Bounds bounds_;
    ViewerCamera camera_;
    /// Where `V` puts the eye and what it looks at: the scan's sensor, when it records one.
    std::optional<std::pair<glm::dvec3, glm::dvec3>> sensorLook_;
    std::unique_ptr<ScanLoadJob> loading_;
    // A streamed scan (COPC, EPT): its source, the nodes on screen, the job loading a view's,
    // the camera as last seen and since when it rests, and the view last refined for.
    std::shared_ptr<const lod::CachedNodeSource> streamed_;
    std::vector<std::size_t> streamedNodes_;
    std::unique_ptr<StreamedViewJob> refining_;
    bool shownProvisional_ = false;      // the nodes on screen are PreparedScan::provisional
    std::unique_ptr<Arrival> arriving_;  // the next set of nodes, while it uploads
    int uploadFrames_ = 0;               // frames that uploaded nodes (unattended runs print it)
    /// A scan loaded whole: its local spacing and normals, estimated after its provisional
    /// first picture (reads scan_: declared after it, so that it goes first).
    std::unique_ptr<BackgroundJob<std::optional<CompletedSpacing>>> completing_;
    std::optional<Camera> stillCamera_;
    double stillSince_ = 0.0;
    std::optional<Camera> refinedCamera_;
    std::uint64_t refinedBudget_ = 0;  // the settings' point budget it was refined with
    bool viewNodesShown_ = false;      // a view's own nodes came since the scan opened
    double openedAt_ = 0.0;            // glfwGetTime() when the scan on screen began to open
    lod::LodMode openedLod_ = lod::LodMode::Auto;  // the streaming.lod of the last opening
    lod::LodMode shownLod_ = lod::LodMode::Auto;   // that of the scan on screen
    bool reopening_ = false;                       // the opening under way keeps the view
    bool initialScanShown_ = false;
    std::optional<std::string> pendingOpen_;

    // The last pipeline frame: what it showed (to skip identical frames) and whether it worked.
    std::optional<Camera> renderedCamera_;
    std::string renderedSettings_;
    int framesAtRest_ = 0;  // frames rendered since the camera and the settings last changed
    RenderMode renderedMode_ = RenderMode::Points;
    bool renderedImage_ = false;

    // Input.
    DragButton drag_ = DragButton::None;
    glm::dvec2 lastCursor_{0.0};
    double lastClickTime_ = -1.0;
    glm::dvec2 lastClickPosition_{0.0};
    bool flying_ = false;  // a fly key is held: draw continuously
    std::optional<std::string> callbackError_;

    // Frames and the script.
    int frame_ = 0;  // frames that showed the scan
    std::size_t nextAction_ = 0;
    bool exitRequested_ = false;
    std::vector<std::filesystem::path> pendingScreenshots_;
    double lastFrameTime_ = 0.0;
};

}  // namespace subscan::viewer
