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

/// The temporal filter (DESIGN.md §5 step 10): the frame's linear colour over the background,
/// rendered through a camera jittered by jitterFor(), blended into the previous result
/// reprojected to this frame. Writes "history" (RGBA16F: colour over the background, coverage
/// of the surface in alpha) and "historyState" (RG32F: this frame's depth, frames in the pixel's
/// history); the previous frame's pair waits under "previousHistory" and "previousHistoryState".
/// At full resolution it also encodes the picture "image" (Present's work, saving a full-screen
/// pass); a reduced frame leaves "history" to Present, which scales it up. The history restarts
/// when the settings, the image or the resolution change; a still camera averages frames evenly
/// (TemporalSettings::maxFrames).
class TemporalPass final : public RenderPass {
  public:
    explicit TemporalPass(const ShaderSources& sources);

    std::string_view name() const override { return "Temporal"; }
    std::vector<std::string_view> inputs() const override { return {colorInput_, "surfaceDepth"}; }
    std::vector<std::string_view> outputs() const override;
    void execute(FrameContext& frame) override;

    /// The radiance the frame's pipeline leaves ("radiance", "scatteredRadiance"), and whether
    /// this pass encodes the picture (a full-resolution frame).
    void setInput(std::string colorInput, bool writesPicture) {
        colorInput_ = std::move(colorInput);
        writesPicture_ = writesPicture;
    }
    /// The jitter of the next frame through `camera` (without jitter), pipeline pixels: Halton
    /// (2, 3), cycling through TemporalSettings::maxFrames points so a still camera's mean
    /// covers the whole pattern; none while the camera moves, where the jitter's own change
    /// from frame to frame costs more steadiness than its anti-aliasing gains (README,
    /// "Temporal filter").
    glm::dvec2 nextJitter(const Camera& camera, const TemporalSettings& settings);
    /// Forget the history: the next frame starts afresh (a cut in an animation).
    void restart() { previous_.reset(); }

  private:
    /// What the next frame's reprojection needs of this one.
    struct PreviousFrame {
        Camera camera;  // without jitter
        RenderSettings settings;
        int divisor = 1;
        bool moved = false;  // its history was reprojected
    };

    std::string colorInput_ = "radiance";
    bool writesPicture_ = true;
    /// The frame alone, the even mean of a still camera, or the reprojected blend of a moving
    /// one (Temporal.comp's variants in this order, then the same writing the picture).
    enum class Mode { Restart, Still, Moving };

    ComputeStages stages_;
    UniformBlock<gpu::TemporalParams> params_{"Temporal.params"};
    std::optional<PreviousFrame> previous_;
    unsigned frameIndex_ = 0;
};

}  // namespace subscan
