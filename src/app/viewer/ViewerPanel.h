#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/Coloring.h"
#include "gpu/PassTimer.h"
#include "render/RenderSettings.h"

namespace subscan::viewer {

enum class Navigation { Orbit, Fly };

/// The stages the Renderer can show in `mode` (the others need the surface passes).
bool stageAvailable(Stage stage, RenderMode mode);

/// What the panel shows but does not change.
struct PanelStatus {
    std::string scanSource;  // empty until the first scan is shown
    std::string scanFormat;
    std::size_t points = 0;
    double spacing = 0.0;
    double loadMilliseconds = 0.0;
    Coloring coloring = Coloring::Auto;        // what the points' colours show
    std::optional<std::string> loadingSource;  // a load in progress
    // A streamed scan (COPC, EPT): the nodes shown, of how many, of how many points in all
    // (0: loaded whole), and whether the view's nodes are loading.
    std::size_t streamedNodes = 0;
    std::size_t streamedNodesInAll = 0;
    std::uint64_t streamedPointsInAll = 0;
    bool streamingView = false;
    std::size_t uploadingBytes = 0;    // of the view's nodes, still to copy to the GPU
    std::uint64_t nodeCacheBytes = 0;  // decoded nodes kept (lod::CachedNodeSource)
    std::uint64_t nodeCacheBudgetBytes = 0;
    // Seconds from opening the scan (the command's start, or choosing another file) to its
    // first frame, and a streamed scan's to the first frame of the first view's own nodes (a
    // scan loaded whole: the first with its local spacing and normals); 0 until then.
    double firstPictureSeconds = 0.0;
    double viewCompleteSeconds = 0.0;
    bool completingSpacing = false;  // a scan loaded whole: its local spacing and normals come
    double loadingProgress = 0.0;
    std::string glRenderer;
    bool int64Atomics = false;
    double windowFps = 0.0;
    std::vector<PassTiming> passes;  // of the last pipeline frame
    int imageWidth = 0;
    int imageHeight = 0;
    int divisor = 1;      // output pixels per reconstructed pixel and side in the last frame
    std::string message;  // the last notice or error, shown at the bottom
    bool messageIsError = false;
    std::string scatteringRefusal;  // AppliedScattering::refusal(): shown while it lasts
    // Where a light added now comes from: the upper left of the view, whatever the up axis
    // (ViewerCamera::defaultLightDirection), in the scene's coordinates.
    glm::vec3 newLightDirection{-0.5f, 0.8f, 0.4f};
};

/// The scattering settings the pipeline renders with. The panel edits the viewer's settings
/// freely, and some combinations are impossible (checkScatteringSettings: single scattering
/// taking the measured coefficients of a Gaussian-only material); the renderer would refuse
/// every frame of them. Those are not applied: the last scattering settings it accepted stay
/// in effect (the picture stays, and every other setting still applies), and the reason is
/// reported once per refused change, not every frame, until a possible combination comes.
class AppliedScattering {
  public:
    explicit AppliedScattering(ScatteringSettings initial);

    /// Offers the panel's scattering settings; they are taken when checkScatteringSettings
    /// accepts them. Returns the reason when they are refused and differ from those last
    /// offered; nothing otherwise.
    std::optional<std::string> offer(const ScatteringSettings& wanted);
    /// In effect: the last accepted (at first the initial ones).
    const ScatteringSettings& settings() const { return applied_; }
    /// Why the settings last offered are not in effect; empty when they are.
    const std::string& refusal() const { return refusal_; }

  private:
    ScatteringSettings applied_;
    std::string offered_;  // JSON of the settings last offered
    std::string refusal_;
};

/// What the user asked for through the panel this frame.
struct PanelRequests {
    bool screenshot = false;
    bool resetView = false;
    bool frameAll = false;
    std::optional<std::string> openScan;
    std::optional<Coloring> coloring;  // show the points coloured by this instead
    std::optional<std::string> loadSettings;
    std::optional<std::string> saveSettings;
};

/// The Dear ImGui panel: every pipeline setting, the scan, live timings, files. Edits the
/// settings in place; the viewer renders again when they change. Call between ImGui::NewFrame
/// and ImGui::Render.
class ViewerPanel {
  public:
    PanelRequests draw(RenderSettings& settings, Navigation& navigation, bool& redrawEveryFrame,
                       const PanelStatus& status);
    /// Whether a window position lies on the panel as last drawn. ImGui's WantCaptureMouse
    /// lags a frame behind the cursor, so a click that arrives with the move onto the panel
    /// would otherwise reach the camera.
    bool covers(const glm::dvec2& windowPosition) const;

  private:
    void drawScan(const PanelStatus& status, StreamingSettings& streaming, PanelRequests& requests);
    void drawPerformance(const PanelStatus& status, bool& redrawEveryFrame);
    void drawView(RenderSettings& settings, Navigation& navigation, const PanelStatus& status,
                  PanelRequests& requests);
    void drawSurface(SurfaceSettings& surface);
    void drawShading(ShadingSettings& shading, const glm::vec3& newLightDirection);
    void drawScattering(ScatteringSettings& scattering);
    void drawFiles(PanelRequests& requests);

    glm::vec2 topLeft_{0.0f};
    glm::vec2 bottomRight_{0.0f};
    std::string openPath_;
    std::string settingsPath_ = "subscan-settings.json";
};

}  // namespace subscan::viewer
