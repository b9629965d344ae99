#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>

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
    std::optional<std::string> loadingSource;  // a load in progress
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
};

/// What the user asked for through the panel this frame.
struct PanelRequests {
    bool screenshot = false;
    bool resetView = false;
    bool frameAll = false;
    std::optional<std::string> openScan;
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
    void drawScan(const PanelStatus& status, PanelRequests& requests);
    void drawPerformance(const PanelStatus& status, bool& redrawEveryFrame);
    void drawView(RenderSettings& settings, Navigation& navigation, const PanelStatus& status,
                  PanelRequests& requests);
    void drawSurface(SurfaceSettings& surface);
    void drawShading(ShadingSettings& shading);
    void drawScattering(ScatteringSettings& scattering);
    void drawFiles(PanelRequests& requests);

    glm::vec2 topLeft_{0.0f};
    glm::vec2 bottomRight_{0.0f};
    std::string openPath_;
    std::string settingsPath_ = "subscan-settings.json";
};

}  // namespace subscan::viewer
