#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include <glm/vec3.hpp>
#include <nlohmann/json_fwd.hpp>

#include "gpu/GpuClear.h"
#include "gpu/PassTimer.h"
#include "lod/NodeSource.h"
#include "render/ScatteringSettings.h"
#include "render/SurfaceSettings.h"

namespace subscan {

/// What the frame pipeline draws.
enum class RenderMode {
    Points,    // compute-rasterized 1-pixel points (the input of the reconstruction)
    PointsGl,  // baseline: GL_POINTS, 1 pixel
    Splats,    // baseline: GL_POINTS of pointSize pixels with depth test (common viewers)
    Surface,   // screen-space reconstruction, shaded
    Sss,       // the surface with screen-space subsurface scattering
};

/// An intermediate buffer of the surface pipeline shown instead of the final image (the panels
/// of the paper's Figure 2).
enum class Stage { Final, Depth, Pyramid, Visibility, Pull, Push, Fill, Normals, Shaded };

/// Which compute rasterizer runs: Auto takes the one-pass 64-bit path where the driver has
/// 64-bit atomics and the two-pass 32-bit path elsewhere; the others force one (tests, bench).
enum class RasterPath { Auto, Int64, TwoPass32 };

/// The pixels the surface and sss modes reconstruct, shade and scatter before Present scales
/// the picture to the output: every one (Full), one per 2x2 block (Half), or Half only while
/// the points are four or more pixels apart on screen (Auto, a close-up: see
/// ResolutionChooser). The point modes always draw every pixel. Reduced resolution trades about a
/// pixel of the silhouette for speed (bench/README.md has the measurements), so it is a choice,
/// not a default.
enum class Resolution { Full, Half, Auto };

/// Rasterization and presentation.
struct RasterSettings {
    RenderMode mode = RenderMode::Points;
    RasterPath path = RasterPath::Auto;
    float pointSize = 4.0f;                         // splats, in pixels
    glm::vec3 backgroundSrgb{0.19f, 0.19f, 0.19f};  // sRGB-encoded 0..1, like colour pickers
    TimingMode timing = TimingMode::Auto;
    ClearPath clears = ClearPath::Auto;
    Stage stage = Stage::Final;
    int stageLevel = 3;  // the pyramid level the pyramid and pull stages show
    Resolution resolution = Resolution::Full;
    // > 0: a pixel's colour is the mean of its points within this relative depth of the
    // nearest (Schuetz et al. 2021), so it no longer depends on which of them wins; 0: the
    // nearest point's colour.
    float colorBlend = 0.0f;
    // > 0, with the points' own normals: a pixel's normal is the mean of its points' within
    // this many pixel widths (at the nearest's depth) behind the nearest, so it no longer
    // depends on which of them wins, and covers the pixel as its supersampled truth does.
    float normalBlend = 1.0f;

    bool operator==(const RasterSettings&) const = default;
};

/// The temporal filter of the surface and sss modes' pictures (DESIGN.md §5 step 10,
/// render/TemporalPass.h): each frame's camera is jittered by a sub-pixel Halton offset and the
/// frame is blended into the previous result reprojected to it, so a still camera converges to
/// a supersampled picture and a moving one does not flicker.
struct TemporalSettings {
    bool enabled = false;  // off for one-frame stills; the viewer and turntable turn it on
    // The least weight of the new frame while the camera moves. 0.2 rather than the usual 0.1:
    // along eval --temporal's orbits it is as steady (E_t equal or lower) and 0.3-0.4 dB
    // closer to the truth, since each frame's bilinear resampling of the history blurs less.
    float newFrameWeight = 0.2f;
    float clipSigma = 1.0f;  // the reprojected history is clipped to mean ± this many
                             // standard deviations of the new frame's 3x3 neighbourhood
    int maxFrames = 256;     // a still camera averages this many frames evenly, then slides

    bool operator==(const TemporalSettings&) const = default;
};

/// How a COPC file or EPT dataset is read (docs/surveys.md): streamed by its levels of detail
/// or whole (lod::LodMode), and the most points a streamed view loads (0: the renderer's
/// default, lod::pointBudgetFor).
struct StreamingSettings {
    lod::LodMode lod = lod::LodMode::Auto;
    std::uint64_t pointBudget = 0;
    /// The viewer's decoded nodes kept in memory (lod::CachedNodeSource), in MiB; read when a
    /// scan opens. At the software renderer's budget a view's nodes take about 20 MiB (1 M
    /// points of position, colour, intensity and class): 512 holds some 25 views and keeps the
    /// viewer within 1.5 GB (bench/README.md).
    std::uint64_t nodeCacheMegabytes = 512;
    /// What the viewer copies of a view's new nodes to the GPU in one frame, in MiB; the nodes
    /// before them show until all have arrived. 32 MiB takes about 3 ms over PCIe 3.0 x16 (12
    /// GB/s), a fifth of a 60 Hz frame: a GPU budget's 10 M points with their local spacing
    /// (some 240 MB) arrive in 8 frames. llvmpipe reads positions and colours in place and
    /// copies 12 bytes a point: its 1 M-point views arrive in one.
    std::uint64_t uploadMegabytesPerFrame = 32;

    bool operator==(const StreamingSettings&) const = default;
};

/// Every setting of a frame, one struct per concern; the JSON the CLI's --settings and the
/// viewer read and write: {"raster": {...}, "surface": {...}, "shading": {...},
/// "scattering": {...}, "temporal": {...}, "streaming": {...}}.
struct RenderSettings {
    RasterSettings raster;
    SurfaceSettings surface;
    ShadingSettings shading;
    ScatteringSettings scattering;
    TemporalSettings temporal;
    StreamingSettings streaming;

    bool operator==(const RenderSettings&) const = default;
};

/// The settings file the CLI (--settings) and the viewer share; throws subscan::Error naming the
/// file and the bad setting. Absent keys keep the values of `defaults`.
RenderSettings readSettingsFile(const std::filesystem::path& path,
                                const RenderSettings& defaults = {});
void writeSettingsFile(const std::filesystem::path& path, const RenderSettings& settings);

void to_json(nlohmann::json& json, const RasterSettings& settings);
void from_json(const nlohmann::json& json, RasterSettings& settings);
void to_json(nlohmann::json& json, const TemporalSettings& settings);
void from_json(const nlohmann::json& json, TemporalSettings& settings);
void to_json(nlohmann::json& json, const StreamingSettings& settings);
void from_json(const nlohmann::json& json, StreamingSettings& settings);
void to_json(nlohmann::json& json, const RenderSettings& settings);
void from_json(const nlohmann::json& json, RenderSettings& settings);

/// Names as the CLI and JSON spell them; the parsers throw subscan::Error listing the choices.
std::string toString(RenderMode mode);
RenderMode parseRenderMode(std::string_view text);
std::string toString(RasterPath path);
RasterPath parseRasterPath(std::string_view text);
std::string toString(Stage stage);
Stage parseStage(std::string_view text);
std::string toString(Resolution resolution);
Resolution parseResolution(std::string_view text);

/// Whether `mode` reconstructs a surface (the surface and sss modes).
bool reconstructsSurface(RenderMode mode);
/// Whether `stage` is a finished picture rather than an intermediate image of the pipeline.
bool isFinalImage(Stage stage);
/// Whether a frame runs the temporal filter: enabled, in a mode that reconstructs, for its
/// final picture.
bool filtersTemporally(const RenderSettings& settings);
/// Whether the frame records its points' sub-pixel cells and places the outline by them
/// (SurfaceSettings::subpixelOutline in a mode that reconstructs the surface).
bool placesOutlineBySubpixels(const RenderSettings& settings);
/// Whether the frame's normals are the points' own, carried by pull-push (SurfaceSettings::normals
/// Points, as the renderer resolves Auto, in a mode that reconstructs the surface).
bool usesPointNormals(const RenderSettings& settings);
/// Whether the frame's screen-space normals follow the surface towards the outline, which they
/// find in "surfaceDepth" (SurfaceSettings::outlineNormals in a mode that reconstructs the
/// surface with screen-space normals).
bool followsNormalsToOutline(const RenderSettings& settings);
/// Frames a camera at rest renders through the temporal filter before its picture counts as
/// finished (the viewer then idles; `render` with the filter on averages this many): 32 jitter
/// offsets put an edge pixel's coverage within 1/32 of its supersampled value.
inline constexpr int kTemporalRestFrames = 32;

}  // namespace subscan
