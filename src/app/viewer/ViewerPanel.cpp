#include "app/viewer/ViewerPanel.h"

#include <algorithm>
#include <span>
#include <string>

#include <imgui.h>
#include <imgui_stdlib.h>
#include <glm/geometric.hpp>

#include "shared/bindings.h"
#include "sss/MaterialLibrary.h"

namespace subscan::viewer {

namespace {

constexpr RenderMode kModes[] = {RenderMode::Points, RenderMode::PointsGl, RenderMode::Splats,
                                 RenderMode::Surface, RenderMode::Sss};
constexpr Stage kStages[] = {Stage::Final,      Stage::Depth,   Stage::Pyramid,
                             Stage::Visibility, Stage::Pull,    Stage::Push,
                             Stage::Fill,       Stage::Normals, Stage::Shaded};
constexpr RasterPath kRasterPaths[] = {RasterPath::Auto, RasterPath::Int64, RasterPath::TwoPass32};
constexpr Resolution kResolutions[] = {Resolution::Full, Resolution::Half, Resolution::Auto};
constexpr std::pair<TimingMode, const char*> kTimings[] = {
    {TimingMode::Auto, "auto"},
    {TimingMode::GpuQueries, "GPU queries"},
    {TimingMode::FinishAndClock, "glFinish + clock"},
};
constexpr AlbedoPlacement kAlbedoPlacements[] = {
    AlbedoPlacement::PreScatter, AlbedoPlacement::PostScatter, AlbedoPlacement::Split};
constexpr SceneUnit kUnits[] = {SceneUnit::Millimetre, SceneUnit::Centimetre, SceneUnit::Metre,
                                SceneUnit::Inch};

constexpr ImGuiSliderFlags kLogarithmic = ImGuiSliderFlags_Logarithmic;
// Colours that are radiances: linear and allowed above 1.
constexpr ImGuiColorEditFlags kRadiance = ImGuiColorEditFlags_Float | ImGuiColorEditFlags_HDR;

/// A combo over `choices`, labelled by `name`; true when the user picked another one.
template <class T, class Name>
bool choiceCombo(const char* label, T& value, std::span<const T> choices, Name name,
                 bool (*available)(T, RenderMode) = nullptr, RenderMode mode = {}) {
    bool changed = false;
    if (ImGui::BeginCombo(label, std::string(name(value)).c_str())) {
        for (const T& choice : choices) {
            if (available != nullptr && !available(choice, mode)) {
                continue;
            }
            const bool selected = choice == value;
            if (ImGui::Selectable(std::string(name(choice)).c_str(), selected) && !selected) {
                value = choice;
                changed = true;
            }
            if (selected) {
                ImGui::SetItemDefaultFocus();
            }
        }
        ImGui::EndCombo();
    }
    return changed;
}

/// 1099005 -> "1,099,005".
std::string groupedThousands(std::size_t value) {
    const std::string digits = std::to_string(value);
    std::string grouped;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i > 0 && (digits.size() - i) % 3 == 0) {
            grouped += ',';
        }
        grouped += digits[i];
    }
    return grouped;
}

void helpTooltip(const char* text) {
    if (ImGui::IsItemHovered()) {
        ImGui::SetTooltip("%s", text);
    }
}

}  // namespace

bool stageAvailable(Stage stage, RenderMode mode) {
    return reconstructsSurface(mode) || stage == Stage::Final || stage == Stage::Depth;
}

PanelRequests ViewerPanel::draw(RenderSettings& settings, Navigation& navigation,
                                bool& redrawEveryFrame, const PanelStatus& status) {
    PanelRequests requests;
    const ImGuiViewport* viewport = ImGui::GetMainViewport();
    ImGui::SetNextWindowPos(ImVec2(8.0f, 8.0f), ImGuiCond_FirstUseEver);
    // At most half of a small window, so that the scan stays visible beside the panel.
    const float width = std::clamp(0.5f * viewport->Size.x, 200.0f, 360.0f);
    ImGui::SetNextWindowSize(ImVec2(width, std::min(viewport->Size.y - 16.0f, 760.0f)),
                             ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowBgAlpha(0.85f);
    const bool expanded = ImGui::Begin("subscan");
    const ImVec2 position = ImGui::GetWindowPos();
    const ImVec2 size = ImGui::GetWindowSize();
    topLeft_ = {position.x, position.y};
    bottomRight_ = {position.x + size.x, position.y + size.y};
    if (expanded) {
        ImGui::PushItemWidth(-150.0f);
        drawScan(status, requests);
        drawPerformance(status, redrawEveryFrame);
        drawView(settings, navigation, status, requests);
        if (ImGui::CollapsingHeader("Surface reconstruction")) {
            drawSurface(settings.surface);
        }
        if (ImGui::CollapsingHeader("Shading")) {
            drawShading(settings.shading);
        }
        if (ImGui::CollapsingHeader("Subsurface scattering")) {
            drawScattering(settings.scattering);
        }
        drawFiles(requests);
        if (ImGui::CollapsingHeader("Controls")) {
            ImGui::TextUnformatted(
                "left drag      orbit (fly: look around)\n"
                "right/middle   pan\n"
                "wheel          zoom to the cursor\n"
                "double click   orbit around that point\n"
                "R / F          reset view / frame all\n"
                "C              orbit <-> fly (WASD, Q/E,\n"
                "               Shift faster)\n"
                "P              screenshot + camera.json\n"
                "Tab            hide this panel\n"
                "Esc            quit\n"
                "drop a file    open it");
        }
        ImGui::PopItemWidth();
        if (!status.message.empty()) {
            ImGui::Separator();
            if (status.messageIsError) {
                ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
            }
            ImGui::TextWrapped("%s", status.message.c_str());
            if (status.messageIsError) {
                ImGui::PopStyleColor();
            }
        }
    }
    ImGui::End();
    return requests;
}

bool ViewerPanel::covers(const glm::dvec2& windowPosition) const {
    return windowPosition.x >= topLeft_.x && windowPosition.y >= topLeft_.y &&
           windowPosition.x < bottomRight_.x && windowPosition.y < bottomRight_.y;
}

void ViewerPanel::drawScan(const PanelStatus& status, PanelRequests& requests) {
    if (!ImGui::CollapsingHeader("Scan", ImGuiTreeNodeFlags_DefaultOpen)) {
        return;
    }
    if (!status.scanSource.empty()) {
        ImGui::TextWrapped("%s", status.scanSource.c_str());
        ImGui::TextWrapped("%s", status.scanFormat.c_str());
        ImGui::Text("%s points, h = %.4g", groupedThousands(status.points).c_str(), status.spacing);
        ImGui::Text("loaded in %.0f ms", status.loadMilliseconds);
    }
    if (status.loadingSource) {
        ImGui::TextWrapped("loading %s", status.loadingSource->c_str());
        ImGui::ProgressBar(static_cast<float>(status.loadingProgress), ImVec2(-1.0f, 0.0f));
    }
    ImGui::SetNextItemWidth(-ImGui::CalcTextSize("Open").x -
                            3.0f * ImGui::GetStyle().FramePadding.x -
                            ImGui::GetStyle().ItemSpacing.x);
    ImGui::InputTextWithHint("##open", "file or synthetic:NAME", &openPath_);
    ImGui::SameLine();
    if (ImGui::Button("Open") && !openPath_.empty()) {
        requests.openScan = openPath_;
    }
    helpTooltip("Or drop a file on the window.");
}

void ViewerPanel::drawPerformance(const PanelStatus& status, bool& redrawEveryFrame) {
    if (!ImGui::CollapsingHeader("Performance", ImGuiTreeNodeFlags_DefaultOpen)) {
        return;
    }
    double total = 0.0;
    for (const PassTiming& pass : status.passes) {
        total += pass.milliseconds;
    }
    ImGui::Text("window %.0f FPS", status.windowFps);
    if (!status.passes.empty()) {
        ImGui::Text("pipeline %.2f ms (%.0f FPS) at %dx%d%s", total,
                    total > 0.0 ? 1000.0 / total : 0.0, status.imageWidth, status.imageHeight,
                    status.divisor == 2 ? ", surface at half" : "");
    }
    ImGui::Checkbox("redraw every frame", &redrawEveryFrame);
    helpTooltip(
        "Render the pipeline every frame even when nothing changed (for measuring); otherwise "
        "it renders only after a change.");
    if (!status.passes.empty() &&
        ImGui::BeginTable("passes", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingStretchProp)) {
        for (const PassTiming& pass : status.passes) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::TextUnformatted(pass.pass.c_str());
            ImGui::TableNextColumn();
            ImGui::Text("%8.2f ms", pass.milliseconds);
        }
        ImGui::EndTable();
    }
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("%s", status.glRenderer.c_str());
    ImGui::PopStyleColor();
}

void ViewerPanel::drawView(RenderSettings& settings, Navigation& navigation,
                           const PanelStatus& status, PanelRequests& requests) {
    if (!ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) {
        return;
    }
    RasterSettings& raster = settings.raster;
    const auto modeName = [](RenderMode mode) { return toString(mode); };
    if (choiceCombo<RenderMode>("mode", raster.mode, kModes, modeName) &&
        !stageAvailable(raster.stage, raster.mode)) {
        raster.stage = Stage::Final;
    }
    choiceCombo<Stage>(
        "stage", raster.stage, kStages, [](Stage stage) { return toString(stage); }, stageAvailable,
        raster.mode);
    helpTooltip("An intermediate buffer of the pipeline instead of the final image.");
    if (reconstructsSurface(raster.mode)) {
        choiceCombo<Resolution>("resolution", raster.resolution, kResolutions,
                                [](Resolution resolution) { return toString(resolution); });
        helpTooltip(
            "Pixels the surface is reconstructed at before scaling to the window. half: "
            "about half the frame time, a pixel of the silhouette lost; auto: half while the "
            "points are 4 or more pixels apart (close-ups of sparse scans).");
    }
    if (raster.stage == Stage::Pyramid || raster.stage == Stage::Pull) {
        ImGui::SliderInt("stage level", &raster.stageLevel, 0, SUBSCAN_MAX_PYRAMID_LEVELS - 1);
    }
    if (raster.mode == RenderMode::Splats) {
        ImGui::SliderFloat("point size (px)", &raster.pointSize, 1.0f, 32.0f, "%.1f");
    }
    if (raster.mode != RenderMode::PointsGl && raster.mode != RenderMode::Splats) {
        choiceCombo<RasterPath>("rasterizer", raster.path, kRasterPaths,
                                [](RasterPath path) { return toString(path); });
        helpTooltip(status.int64Atomics
                        ? "This GPU has 64-bit atomics: auto takes the one-pass path."
                        : "This GPU lacks 64-bit atomics: int64 fails, auto takes two passes.");
    }
    auto timingName = [](TimingMode mode) {
        for (const auto& [value, name] : kTimings) {
            if (value == mode) {
                return std::string(name);
            }
        }
        return std::string("?");
    };
    constexpr TimingMode kTimingModes[] = {TimingMode::Auto, TimingMode::GpuQueries,
                                           TimingMode::FinishAndClock};
    choiceCombo<TimingMode>("pass timing", raster.timing, kTimingModes, timingName);
    ImGui::ColorEdit3("background", &raster.backgroundSrgb.x);

    int navigationIndex = navigation == Navigation::Orbit ? 0 : 1;
    ImGui::RadioButton("orbit", &navigationIndex, 0);
    ImGui::SameLine();
    ImGui::RadioButton("fly (C)", &navigationIndex, 1);
    navigation = navigationIndex == 0 ? Navigation::Orbit : Navigation::Fly;
    if (ImGui::Button("Reset view (R)")) {
        requests.resetView = true;
    }
    ImGui::SameLine();
    if (ImGui::Button("Frame all (F)")) {
        requests.frameAll = true;
    }
}

void ViewerPanel::drawSurface(SurfaceSettings& surface) {
    ImGui::SliderFloat("visibility radius (h)", &surface.visibilityRadius, 0.5f, 32.0f, "%.2f",
                       kLogarithmic);
    helpTooltip("Hidden point removal looks this far for occluders.");
    ImGui::SliderFloat("visibility threshold", &surface.visibilityThreshold, 0.0f, 1.0f, "%.3f");
    helpTooltip("tau: a point is visible when the mean of its 8 smallest omegas reaches it.");
    ImGui::Checkbox("silhouette edge rule", &surface.edgeRule);
    ImGui::SliderFloat("pull depth slope", &surface.pullDepthSlope, 0.5f, 64.0f, "%.2f",
                       kLogarithmic);
    helpTooltip("The pull keeps children within this many texel widths behind the nearest one.");
    ImGui::SliderFloat("fill radius (h)", &surface.fillRadius, 0.25f, 16.0f, "%.2f", kLogarithmic);
    helpTooltip("The expected gap between points; fill beyond it is background.");
    ImGui::SliderInt("fill directions", &surface.fillDirections, 1, 8);
    ImGui::SliderFloat("normal radius (h)", &surface.normalRadius, 0.25f, 16.0f, "%.2f",
                       kLogarithmic);
    ImGui::Checkbox("skip the screen around the points", &surface.restrictToPoints);
    helpTooltip(
        "Passes after rasterization work only inside the points' bounds (the same "
        "picture, faster when the scan covers part of the window).");
}

void ViewerPanel::drawShading(ShadingSettings& shading) {
    ImGui::ColorEdit3("head light", &shading.headLight.x, kRadiance);
    ImGui::ColorEdit3("ambient", &shading.ambient.x, kRadiance);
    ImGui::SliderFloat("specular", &shading.specular, 0.0f, 1.0f, "%.3f");
    ImGui::SliderFloat("shininess", &shading.shininess, 1.0f, 1000.0f, "%.0f", kLogarithmic);
    std::size_t removed = shading.lights.size();
    for (std::size_t i = 0; i < shading.lights.size(); ++i) {
        DirectionalLight& light = shading.lights[i];
        ImGui::PushID(static_cast<int>(i));
        ImGui::Text("light %zu", i + 1);
        ImGui::SameLine();
        if (ImGui::SmallButton("remove")) {
            removed = i;
        }
        const glm::vec3 before = light.direction;
        if (ImGui::SliderFloat3("direction", &light.direction.x, -1.0f, 1.0f, "%.2f") &&
            !(glm::dot(light.direction, light.direction) > 1e-6f)) {
            light.direction = before;  // a zero direction has no light to give
        }
        helpTooltip("Towards the light, in scene coordinates.");
        ImGui::ColorEdit3("radiance", &light.radiance.x, kRadiance);
        ImGui::PopID();
    }
    if (removed < shading.lights.size()) {
        shading.lights.erase(shading.lights.begin() + static_cast<std::ptrdiff_t>(removed));
    }
    ImGui::BeginDisabled(shading.lights.size() >= SUBSCAN_MAX_LIGHTS);
    if (ImGui::Button("Add a directional light")) {
        shading.lights.push_back({glm::vec3(-0.5f, 0.8f, 0.4f), glm::vec3(1.0f)});
    }
    ImGui::EndDisabled();
}

void ViewerPanel::drawScattering(ScatteringSettings& scattering) {
    ImGui::TextDisabled("used by the sss mode");
    const std::vector<Material>& materials = materialLibrary();
    if (ImGui::BeginCombo("material", scattering.material.c_str())) {
        for (const Material& material : materials) {
            const bool selected = material.name == scattering.material;
            if (ImGui::Selectable(material.name.c_str(), selected)) {
                scattering.material = material.name;
            }
            helpTooltip(material.description.c_str());
            if (selected) {
                ImGui::SetItemDefaultFocus();
            }
        }
        ImGui::EndCombo();
    }
    choiceCombo<SceneUnit>("scan unit", scattering.unit, kUnits,
                           [](SceneUnit unit) { return toString(unit); });
    helpTooltip("The length unit of the scan's coordinates; profiles are in millimetres.");
    ImGui::SliderFloat("radius scale", &scattering.scale, 0.01f, 100.0f, "%.3f", kLogarithmic);
    choiceCombo<AlbedoPlacement>("albedo", scattering.albedo, kAlbedoPlacements,
                                 [](AlbedoPlacement placement) { return toString(placement); });
    helpTooltip("Where the colour enters the blur: before it, after it, or sqrt on both sides.");
    ImGui::SliderInt("max taps", &scattering.maxTaps, 1, 128);
}

void ViewerPanel::drawFiles(PanelRequests& requests) {
    if (!ImGui::CollapsingHeader("Files", ImGuiTreeNodeFlags_DefaultOpen)) {
        return;
    }
    ImGui::InputText("settings file", &settingsPath_);
    helpTooltip("The JSON that `subscan render --settings` reads.");
    if (ImGui::Button("Save settings") && !settingsPath_.empty()) {
        requests.saveSettings = settingsPath_;
    }
    ImGui::SameLine();
    if (ImGui::Button("Load settings") && !settingsPath_.empty()) {
        requests.loadSettings = settingsPath_;
    }
    if (ImGui::Button("Screenshot (P)")) {
        requests.screenshot = true;
    }
    helpTooltip("A PNG of the window, with NAME.camera.json and NAME.settings.json beside it.");
}

}  // namespace subscan::viewer
