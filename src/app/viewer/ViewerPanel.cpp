#include "app/viewer/ViewerPanel.h"

#include <algorithm>
#include <cstdio>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include <imgui.h>
#include <imgui_stdlib.h>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "core/Error.h"
#include "render/SettingsJson.h"
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
constexpr NormalSource kNormalSources[] = {NormalSource::Auto, NormalSource::Points,
                                           NormalSource::Screen};
constexpr std::pair<TimingMode, const char*> kTimings[] = {
    {TimingMode::Auto, "auto"},
    {TimingMode::GpuQueries, "GPU queries"},
    {TimingMode::FinishAndClock, "glFinish + clock"},
};
constexpr AlbedoPlacement kAlbedoPlacements[] = {
    AlbedoPlacement::PreScatter, AlbedoPlacement::PostScatter, AlbedoPlacement::Split};
constexpr SceneUnit kUnits[] = {SceneUnit::Millimetre, SceneUnit::Centimetre, SceneUnit::Metre,
                                SceneUnit::Inch};
constexpr ScatteringMethod kMethods[] = {ScatteringMethod::Gaussian, ScatteringMethod::Single,
                                         ScatteringMethod::Both};
constexpr CoefficientSource kSources[] = {CoefficientSource::Material, CoefficientSource::Color};
constexpr LightPath kLightPaths[] = {LightPath::LightMap, LightPath::Screen};
constexpr LightSpace kLightSpaces[] = {LightSpace::World, LightSpace::View};
// The ranges checkScatteringSettings allows, a little inside where its bounds are open.
constexpr float kMinMeanFreePathMm = 0.01f;
constexpr float kMaxMeanFreePathMm = 1000.0f;
constexpr float kMinEta = 1.0f;
constexpr float kMaxEta = 3.0f;
constexpr float kMaxPhaseG = 0.95f;
constexpr int kMaxSingleSamples = 64;

constexpr ImGuiSliderFlags kLogarithmic = ImGuiSliderFlags_Logarithmic;
// Ctrl+click typing stays inside the slider's range too.
constexpr ImGuiSliderFlags kClamp = ImGuiSliderFlags_AlwaysClamp;
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

const Material* libraryMaterial(const std::string& name) {
    for (const Material& material : materialLibrary()) {
        if (material.name == name) {
            return &material;
        }
    }
    return nullptr;
}

bool hasMeasuredCoefficients(const Material& material) {
    return material.sigmaSPrime.has_value() && material.sigmaA.has_value();
}

/// `text` with the Greek of the optics (the material library's sentences say σs′, σa, η)
/// spelt out: ImGui's built-in font has Latin-1 only and would draw them as '?'.
std::string inPanelFont(std::string text) {
    constexpr std::pair<std::string_view, std::string_view> kSpellings[] = {
        {"σ", "sigma_"}, {"′", "'"}, {"η", "eta"}, {"α", "alpha"}};
    for (const auto& [symbol, spelling] : kSpellings) {
        for (std::size_t at = text.find(symbol); at != std::string::npos;
             at = text.find(symbol, at + spelling.size())) {
            text.replace(at, symbol.size(), spelling);
        }
    }
    return text;
}

/// Wrapped text, red for an error.
void messageText(const std::string& text, bool error) {
    if (error) {
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
    }
    ImGui::TextWrapped("%s", inPanelFont(text).c_str());
    if (error) {
        ImGui::PopStyleColor();
    }
}

}  // namespace

AppliedScattering::AppliedScattering(ScatteringSettings initial) : applied_(std::move(initial)) {}

std::optional<std::string> AppliedScattering::offer(const ScatteringSettings& wanted) {
    std::string offered = nlohmann::json(wanted).dump();
    if (offered == offered_) {
        return std::nullopt;
    }
    offered_ = std::move(offered);
    try {
        checkScatteringSettings(wanted);
    } catch (const Error& error) {
        refusal_ = error.what();
        return refusal_;
    }
    applied_ = wanted;
    refusal_.clear();
    return std::nullopt;
}

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
        drawScan(status, settings.streaming, requests);
        drawPerformance(status, redrawEveryFrame);
        drawView(settings, navigation, status, requests);
        if (ImGui::CollapsingHeader("Surface reconstruction")) {
            drawSurface(settings.surface);
        }
        if (ImGui::CollapsingHeader("Shading")) {
            drawShading(settings.shading, status.newLightDirection);
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
                "L + left drag  turn light 1 around the\n"
                "               scan (L adds one if none)\n"
                "R / F          reset view / frame all\n"
                "V              view from the scan's sensor\n"
                "C              orbit <-> fly (WASD, Q/E,\n"
                "               Shift faster)\n"
                "P              screenshot + camera.json\n"
                "Tab            hide this panel\n"
                "Esc            quit\n"
                "drop a file    open it");
        }
        ImGui::PopItemWidth();
        if (!status.scatteringRefusal.empty()) {
            // Stays while it lasts, whatever notices come after it.
            ImGui::Separator();
            messageText(
                "Not applied (the picture keeps the last scattering settings that "
                "work): " +
                    status.scatteringRefusal,
                true);
        }
        if (!status.message.empty() && status.message != status.scatteringRefusal) {
            ImGui::Separator();
            messageText(status.message, status.messageIsError);
        }
    }
    ImGui::End();
    return requests;
}

bool ViewerPanel::covers(const glm::dvec2& windowPosition) const {
    return windowPosition.x >= topLeft_.x && windowPosition.y >= topLeft_.y &&
           windowPosition.x < bottomRight_.x && windowPosition.y < bottomRight_.y;
}

void ViewerPanel::drawScan(const PanelStatus& status, StreamingSettings& streaming,
                           PanelRequests& requests) {
    if (!ImGui::CollapsingHeader("Scan", ImGuiTreeNodeFlags_DefaultOpen)) {
        return;
    }
    if (!status.scanSource.empty()) {
        ImGui::TextWrapped("%s", status.scanSource.c_str());
        ImGui::TextWrapped("%s", status.scanFormat.c_str());
        ImGui::Text("%s points, h = %.4g", groupedThousands(status.points).c_str(), status.spacing);
        const auto lodName = [](lod::LodMode mode) { return nameOf(lod::kLodModeNames, mode); };
        constexpr lod::LodMode kLodModes[] = {lod::LodMode::Auto, lod::LodMode::On,
                                              lod::LodMode::Off};
        // The viewer opens the scan again when this changes.
        choiceCombo("levels of detail", streaming.lod, std::span<const lod::LodMode>(kLodModes),
                    lodName);
        helpTooltip(
            "auto: COPC files and EPT datasets stream by their levels of detail, the view's "
            "nodes within the point budget; every other file loads whole. on: only streamed "
            "sources open. off: every file loads whole. A change opens the scan again.");
        if (status.streamedNodesInAll > 0) {
            ImGui::TextWrapped("streamed: %zu of %zu nodes, of %s points%s", status.streamedNodes,
                               status.streamedNodesInAll,
                               groupedThousands(status.streamedPointsInAll).c_str(),
                               status.streamingView ? "; loading the view's nodes" : "");
            if (status.uploadingBytes > 0) {
                ImGui::Text("uploading the next nodes: %.0f MiB left",
                            status.uploadingBytes / 1048576.0);
            }
            ImGui::Text("node cache: %.0f of %.0f MiB", status.nodeCacheBytes / 1048576.0,
                        status.nodeCacheBudgetBytes / 1048576.0);
            helpTooltip(
                "Decoded nodes kept in memory (settings file: streaming.node_cache_megabytes); "
                "the least recently used leave first.");
            // Applied when Enter is pressed: every change reloads the view's nodes.
            constexpr std::uint64_t kStep = 100'000, kFastStep = 1'000'000;
            ImGui::InputScalar("point budget", ImGuiDataType_U64, &streaming.pointBudget, &kStep,
                               &kFastStep, nullptr, ImGuiInputTextFlags_EnterReturnsTrue);
            helpTooltip(
                "The most points a view of this survey loads; 0: 1,000,000 on software "
                "rendering, 10,000,000 on a GPU. The view's nodes load again once the camera "
                "rests.");
        }
        ImGui::Text("loaded in %.0f ms", status.loadMilliseconds);
        if (status.firstPictureSeconds > 0.0) {
            ImGui::Text("first picture %.2f s after opening", status.firstPictureSeconds);
        }
        if (status.completingSpacing) {
            ImGui::TextUnformatted("estimating the local spacing and normals...");
        } else if (status.viewCompleteSeconds > 0.0 && status.streamedNodesInAll > 0) {
            ImGui::Text("the view's nodes shown %.2f s after opening", status.viewCompleteSeconds);
        } else if (status.viewCompleteSeconds > 0.0) {
            ImGui::Text("with its local spacing and normals %.2f s after opening",
                        status.viewCompleteSeconds);
        }
        constexpr Coloring kColorings[] = {Coloring::Auto,           Coloring::Rgb,
                                           Coloring::Intensity,      Coloring::Height,
                                           Coloring::Classification, Coloring::Uniform};
        Coloring coloring = status.coloring;
        if (choiceCombo("colour", coloring, std::span<const Coloring>(kColorings),
                        [](Coloring c) { return toString(c); })) {
            requests.coloring = coloring;
        }
        helpTooltip(
            "What the points' colours show: auto (their own, else height for Z-up data, else "
            "grey), rgb, intensity, height (a ramp along the up axis), classification (ASPRS "
            "colours), uniform.");
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
        TemporalSettings& temporal = settings.temporal;
        ImGui::Checkbox("temporal filter", &temporal.enabled);
        helpTooltip(
            "Blend each frame into the last, reprojected: steadier while moving; at rest the "
            "camera is jittered by sub-pixel offsets and the frames averaged into an "
            "anti-aliased picture.");
        if (temporal.enabled) {
            ImGui::SliderFloat("new frame weight", &temporal.newFrameWeight, 0.01f, 1.0f, "%.2f");
            helpTooltip("While moving: lower is steadier, higher follows changes sooner.");
        }
    }
    if (raster.stage == Stage::Pyramid || raster.stage == Stage::Pull) {
        ImGui::SliderInt("stage level", &raster.stageLevel, 0, SUBSCAN_MAX_PYRAMID_LEVELS - 1);
    }
    if (raster.mode == RenderMode::Splats) {
        ImGui::SliderFloat("point size (px)", &raster.pointSize, 1.0f, 32.0f, "%.1f");
    }
    if (raster.mode != RenderMode::PointsGl && raster.mode != RenderMode::Splats) {
        float blendPercent = 100.0f * raster.colorBlend;
        if (ImGui::SliderFloat("colour blend (depth %)", &blendPercent, 0.0f, 5.0f, "%.1f")) {
            raster.colorBlend = blendPercent / 100.0f;
        }
        helpTooltip(
            "0: a pixel shows its nearest point's colour. Above 0: the mean colour of its points "
            "within that share of the nearest's depth, so colours stop flickering as points "
            "trade places.");
        if (settings.surface.normals != NormalSource::Screen) {
            ImGui::SliderFloat("normal blend (px)", &raster.normalBlend, 0.0f, 8.0f, "%.1f");
            helpTooltip(
                "With the points' normals, 0: a pixel shows its nearest point's normal. Above 0: "
                "the mean normal of its points within that many pixel widths behind the "
                "nearest, so shading stops flickering where overlapping scans trade places.");
        }
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
    choiceCombo<NormalSource>("normals", surface.normals, kNormalSources,
                              [](NormalSource source) { return toString(source); });
    helpTooltip(
        "points: the points' own normals (the file's, else estimated at load for clouds of up "
        "to 2 M points), carried into the gaps; screen: the paper's, rebuilt from the filled "
        "depth every frame. auto and points: the points' where the scan has them, else the "
        "screen's.");
    ImGui::SliderFloat("normal radius (h)", &surface.normalRadius, 0.25f, 16.0f, "%.2f",
                       kLogarithmic);
    helpTooltip("Smoothing of the screen-space normals.");
    ImGui::Checkbox("local spacing", &surface.localSpacing);
    helpTooltip(
        "Radii scale with each point's own spacing where the scan's density varies (a LiDAR "
        "station); off: the one global h.");
    ImGui::Checkbox("sub-pixel outline", &surface.subpixelOutline);
    helpTooltip(
        "A dense scan's outline runs where its points' sub-pixel cells put it, instead of "
        "through every pixel a point falls in (half a pixel too far out).");
    ImGui::Checkbox("normals towards the outline", &surface.outlineNormals);
    helpTooltip(
        "Normals near the outline follow the surface's turn away from the camera there, so "
        "round objects' rims darken as they should; off: the smoothed normal, too bright.");
    ImGui::Checkbox("skip the screen around the points", &surface.restrictToPoints);
    helpTooltip(
        "Passes after rasterization work only inside the points' bounds (the same "
        "picture, faster when the scan covers part of the window).");
}

void ViewerPanel::drawShading(ShadingSettings& shading, const glm::vec3& newLightDirection) {
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
        helpTooltip(
            light.space == LightSpace::World
                ? "Towards the light, in scene coordinates."
                : "Towards the light, in the view's coordinates (x right, y up, z to you).");
        choiceCombo<LightSpace>("fixed to", light.space, kLightSpaces, [](LightSpace space) {
            return space == LightSpace::World ? "scene" : "view";
        });
        helpTooltip(
            "scene: the light stays put while you orbit; view: it turns with the camera (its "
            "shadows are recomputed whenever the view turns).");
        ImGui::ColorEdit3("radiance", &light.radiance.x, kRadiance);
        ImGui::PopID();
    }
    if (removed < shading.lights.size()) {
        shading.lights.erase(shading.lights.begin() + static_cast<std::ptrdiff_t>(removed));
    }
    ImGui::BeginDisabled(shading.lights.size() >= SUBSCAN_MAX_LIGHTS);
    if (ImGui::Button("Add a directional light")) {
        shading.lights.push_back({newLightDirection, glm::vec3(1.0f)});
    }
    ImGui::EndDisabled();

    ImGui::Separator();
    ImGui::Checkbox("shadows", &shading.shadows);
    helpTooltip(
        "The directional lights cast shadows: each light reconstructs the scan from its own "
        "direction (its light map), again only when it turns. Hold L and drag to turn light 1.");
    ImGui::SliderFloat("shadow bias (h)", &shading.shadowBias, 0.0f, 20.0f, "%.2f", kClamp);
    helpTooltip(
        "How far behind the light's surface, in point spacings, a shadow begins; also how far "
        "the camera's and the light's surfaces may differ for transmission and single "
        "scattering's entries.");
    ImGui::BeginDisabled(!shading.shadows);
    ImGui::SliderFloat("soft edge (h)", &shading.shadowSoftness, 0.0f, 20.0f, "%.2f", kClamp);
    helpTooltip("The width over which a shadow's edge fades, in point spacings.");
    ImGui::EndDisabled();
    int resolution = shading.lightMapResolution;
    if (ImGui::SliderInt("light map texels", &resolution, 0, 4096, resolution == 0 ? "auto" : "%d",
                         kClamp)) {
        // 1..15 would be refused; below the smallest useful size means automatic.
        shading.lightMapResolution = resolution < kMinLightMapResolution ? 0 : resolution;
    }
    helpTooltip("Texels along a light map's longer side; auto: one per point spacing, 64 to 2048.");
}

void ViewerPanel::drawScattering(ScatteringSettings& scattering) {
    ImGui::TextDisabled("used by the sss mode");
    choiceCombo<ScatteringMethod>("method", scattering.method, kMethods,
                                  [](ScatteringMethod method) { return toString(method); });
    helpTooltip(
        "gaussian: the screen-space blur of the diffuse light; single: single scattering added "
        "to the unblurred diffuse light; both: single scattering added to the blurred light.");
    const bool blurs = scattering.method != ScatteringMethod::Single;
    const bool single = scattering.method != ScatteringMethod::Gaussian;
    // Single scattering from the material's coefficients needs a measured material. The
    // combo still offers the Gaussian-only ones, marked: picking one shows why it cannot work
    // (AppliedScattering keeps the picture) instead of an entry that vanishes or greys out
    // depending on two other combos, and the user may be on the way to coefficients=color.
    const bool needsMeasured = single && scattering.coefficients == CoefficientSource::Material;
    if (ImGui::BeginCombo("material", scattering.material.c_str())) {
        for (const Material& material : materialLibrary()) {
            const bool selected = material.name == scattering.material;
            const bool unusable = needsMeasured && !hasMeasuredCoefficients(material);
            const std::string label =
                unusable ? material.name + " (Gaussian only)##" + material.name : material.name;
            if (ImGui::Selectable(label.c_str(), selected)) {
                scattering.material = material.name;
            }
            if (unusable) {
                helpTooltip(
                    "No measured sigma_s' and sigma_a: single scattering needs coefficients "
                    "'color' with it.");
            } else {
                helpTooltip(material.description.c_str());
            }
            if (selected) {
                ImGui::SetItemDefaultFocus();
            }
        }
        ImGui::EndCombo();
    }
    helpTooltip(
        "The Gaussian set of the blur; for single scattering its eta, and with coefficients "
        "'material' its measured sigma_s' and sigma_a.");
    choiceCombo<SceneUnit>("scan unit", scattering.unit, kUnits,
                           [](SceneUnit unit) { return toString(unit); });
    helpTooltip("The length unit of the scan's coordinates; profiles are in millimetres.");
    ImGui::SliderFloat("radius scale", &scattering.scale, 0.01f, 100.0f, "%.3f",
                       kLogarithmic | kClamp);
    helpTooltip("Multiplies every radius of the profile and every mean free path.");

    ImGui::Separator();
    ImGui::TextDisabled(blurs ? "Gaussian blur" : "Gaussian blur (method gaussian or both)");
    ImGui::BeginDisabled(!blurs);
    choiceCombo<AlbedoPlacement>("albedo", scattering.albedo, kAlbedoPlacements,
                                 [](AlbedoPlacement placement) { return toString(placement); });
    helpTooltip("Where the colour enters the blur: before it, after it, or sqrt on both sides.");
    ImGui::SliderInt("max taps", &scattering.maxTaps, 1, 128, "%d", kClamp);
    ImGui::Checkbox("transmission", &scattering.transmission);
    helpTooltip(
        "Directional light through thin parts (ears, fingers, rims lit from behind), from the "
        "light map's thickness and the material's profile.");
    ImGui::EndDisabled();

    ImGui::Separator();
    ImGui::TextDisabled(single ? "single scattering" : "single scattering (method single or both)");
    ImGui::BeginDisabled(!single);
    choiceCombo<CoefficientSource>("coefficients", scattering.coefficients, kSources,
                                   [](CoefficientSource source) { return toString(source); });
    helpTooltip(
        "Where sigma_s' and sigma_a come from: the material's measurement, or per pixel from "
        "the surface colour and the mean free path.");
    choiceCombo<LightPath>("light entry", scattering.lightPath, kLightPaths,
                           [](LightPath path) { return toString(path); });
    helpTooltip(
        "Where a directional light entered: light_map, the first surface the light meets (also "
        "the back of a thin part); screen, a march through what the camera sees.");
    ImGui::BeginDisabled(scattering.coefficients != CoefficientSource::Color);
    // The three values, a button, then the label where the other labels are.
    const ImGuiStyle& style = ImGui::GetStyle();
    const float buttonWidth = ImGui::CalcTextSize("marble").x + 2.0f * style.FramePadding.x;
    ImGui::SetNextItemWidth(
        std::max(ImGui::CalcItemWidth() - buttonWidth - style.ItemInnerSpacing.x, 60.0f));
    ImGui::SliderFloat3("##mean free path", &scattering.meanFreePathMm.x, kMinMeanFreePathMm,
                        kMaxMeanFreePathMm, "%.3g", kLogarithmic | kClamp);
    helpTooltip(
        "Diffuse mean free path l_d = 1/sigma_tr per channel (R G B), in mm (times the radius "
        "scale); used with coefficients 'color'.");
    ImGui::SameLine(0.0f, style.ItemInnerSpacing.x);
    if (ImGui::SmallButton("marble")) {
        scattering.meanFreePathMm = kMarbleMeanFreePathMm;
    }
    helpTooltip("Jensen et al. 2001's marble: a marble-coloured scan gets marble back.");
    ImGui::SameLine(0.0f, style.ItemInnerSpacing.x);
    ImGui::TextUnformatted("mean free path (mm)");
    ImGui::EndDisabled();

    const Material* material = libraryMaterial(scattering.material);
    bool materialEta = !scattering.eta.has_value();
    // "###" keeps the checkbox's identity while its text shows the value.
    char etaLabel[64] = "material's eta###materialEta";
    if (material != nullptr && materialEta) {
        std::snprintf(etaLabel, sizeof etaLabel, "material's eta (%.2f)###materialEta",
                      material->eta);
    }
    if (ImGui::Checkbox(etaLabel, &materialEta)) {
        if (materialEta) {
            scattering.eta.reset();
        } else {
            // The explicit value starts where the material's was.
            scattering.eta = std::clamp(
                material != nullptr ? static_cast<float>(material->eta) : 1.3f, kMinEta, kMaxEta);
        }
    }
    helpTooltip("The relative index of refraction: the material's, or the value below.");
    if (scattering.eta) {
        ImGui::SliderFloat("eta", &*scattering.eta, kMinEta, kMaxEta, "%.3f", kClamp);
    }
    ImGui::SliderFloat("phase g", &scattering.phaseG, -kMaxPhaseG, kMaxPhaseG, "%.2f", kClamp);
    helpTooltip(
        "Henyey-Greenstein asymmetry: below 0 scatters back towards the light, above 0 on "
        "forwards, 0 evenly.");
    ImGui::SliderInt("samples", &scattering.singleSamples, 1, kMaxSingleSamples, "%d", kClamp);
    helpTooltip("Samples along the refracted view ray per pixel.");
    ImGui::EndDisabled();
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
