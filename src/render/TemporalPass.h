#pragma once

#include <optional>
#include <string>

#include <glm/vec2.hpp>

#include "core/Camera.h"
#include "render/ComputeStages.h"
#include "render/RenderPass.h"
#include "render/RenderSettings.h"
#include "shared/bindings.h"

namespace subscan {

/// The Halton (2, 3) point `index` (from 1) centred on 0: each coordinate in (-0.5, 0.5). The
/// first 2^k x 3^k points fill a pixel evenly, so jittered frames average to a supersampled one.
glm::dvec2 haltonJitter(unsigned index);

/// The temporal filter's memory across frames (DESIGN.md §5 step 10): the jitter sequence, the
/// previous frame's camera and settings, and its result in the frame's resources: "history"
/// (RGBA32F: colour over the background, coverage of the surface in alpha) and "historyState"
/// (RG32F: that frame's depth, frames in the pixel's history), the one before waiting under
/// "previousHistory" and "previousHistoryState". Shared by TemporalPass and the surface mode's
/// fused end (FinishSurfacePass), which run render/Temporal.glsl. The history restarts when the
/// settings, the image or the resolution change.
class TemporalHistory {
  public:
    /// The frame alone, the even mean of a still camera, or the reprojected blend of a moving
    /// one.
    enum class Mode { Restart, Still, Moving };

    /// The jitter of the next frame through `camera` (without jitter), pipeline pixels: Halton
    /// (2, 3), cycling through TemporalSettings::maxFrames points so a still camera's mean
    /// covers the whole pattern; none while the camera moves, where the jitter's own change
    /// from frame to frame costs more steadiness than its anti-aliasing gains (docs/temporal.md,
    /// "How it works").
    glm::dvec2 nextJitter(const Camera& camera, const TemporalSettings& settings);
    /// Forget the history: the next frame starts afresh (a cut in an animation).
    void restart() { previous_.reset(); }

    /// The mode of the next frame through the pipeline camera `camera` (with its jitter).
    Mode modeFor(const Camera& camera, const RenderSettings& settings, int divisor) const;
    /// Readies this frame's blend and returns its mode: swaps the history images, sets what
    /// lies outside the frame's region to the background (where the image held an earlier
    /// frame's values; the picture "image", when `picture`, whole), and binds the parameters
    /// (SUBSCAN_UBO_TEMPORAL), the previous result (IN2, IN3), the new one (OUT2, OUT3) and the
    /// picture (OUT0).
    Mode begin(FrameContext& frame, bool picture);
    /// After the dispatch: this frame becomes the one the next reprojects from.
    void end(const FrameContext& frame, Mode mode);

  private:
    struct PreviousFrame {
        Camera camera;  // without jitter
        RenderSettings settings;
        int divisor = 1;
        bool moved = false;  // its history was reprojected
    };

    UniformBlock<gpu::TemporalParams> params_{"Temporal.params"};
    std::optional<PreviousFrame> previous_;
    // Where the history image written next holds a frame's values (written two frames ago:
    // the two images alternate) and where the other one does; elsewhere both hold the
    // background. Unknown after a restart, when the whole image is cleared instead.
    std::optional<TexelRegion> writtenBefore_;
    std::optional<TexelRegion> writtenLast_;
    unsigned frameIndex_ = 0;
};

/// Where TemporalPass finds the frame's depth.
enum class TemporalDepth {
    SurfaceDepth,  // the image "surfaceDepth"; the colour's alpha is the share of the pixel
                   // the surface covers (OutlineCoveragePass)
    ColorAlpha,    // the colour input's alpha (RGBA32F; FinishSurface's "radianceAndDepth",
                   // its colour over the background)
};

/// The temporal filter as its own pass, after shading or scattering (the sss mode, reduced
/// resolution, exports): blends the frame's linear colour into `history`. At full resolution
/// it also encodes the picture "image" (Present's work, saving a full-screen pass); a reduced
/// frame leaves "history" to Present, which scales it up.
class TemporalPass final : public RenderPass {
  public:
    TemporalPass(const ShaderSources& sources, TemporalHistory& history);

    std::string_view name() const override { return "Temporal"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override;
    std::vector<std::string_view> outputs(const RenderSettings&) const override;
    void execute(FrameContext& frame) override;

    /// The radiance the frame's pipeline leaves ("radiance", "scatteredRadiance",
    /// "radianceAndDepth") and where its depth is, and whether this pass encodes the picture
    /// (a full-resolution frame).
    void setInput(std::string colorInput, TemporalDepth depth, bool writesPicture) {
        colorInput_ = std::move(colorInput);
        depth_ = depth;
        writesPicture_ = writesPicture;
    }

  private:
    const ComputeStages& stages();

    const ShaderSources& sources_;
    TemporalHistory& history_;
    std::string colorInput_ = "radiance";
    TemporalDepth depth_ = TemporalDepth::SurfaceDepth;
    bool writesPicture_ = true;
    // Temporal.comp's variants by TemporalDepth, each compiled when first used: by
    // TemporalHistory::Mode, then the same writing the picture.
    std::optional<ComputeStages> stages_[2];
};

}  // namespace subscan
