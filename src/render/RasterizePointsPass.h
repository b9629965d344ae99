#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpu/GlObjects.h"
#include "gpu/ShaderSources.h"
#include "render/RenderPass.h"
#include "shared/bindings.h"

namespace subscan {

/// Compute rasterization of 1-pixel points (DESIGN.md §5.1): per pixel the nearest point,
/// ties to the smaller index. Writes "depth" (R32F linear depth, +inf where empty) and "color"
/// (RGBA16F linear). One 64-bit atomicMin pass where the driver has 64-bit atomics, else two
/// 32-bit passes (depth, then index among points at that depth); both give the same winner.
/// With RasterSettings::colorBlend > 0 the colour is instead the mean of the points within that
/// relative depth of the winner (Schuetz et al. 2021), and with RasterSettings::normalBlend > 0
/// and the points' own normals the normal the mean of theirs within that many pixel widths: the
/// 32-bit path sums them in its index stage, the 64-bit one in a pass after its own.
/// Its per-pixel words live in the frame's resources ("depthIndex" or "pointIndex"), so one
/// pass serves views of any size (the camera's, the lights').
class RasterizePointsPass final : public RenderPass {
  public:
    RasterizePointsPass(const ShaderSources& sources, const GlCapabilities& capabilities);

    std::string_view name() const override { return "RasterizePoints"; }
    std::vector<std::string_view> inputs(const RenderSettings&) const override { return {}; }
    std::vector<std::string_view> outputs(const RenderSettings& settings) const override;
    void execute(FrameContext& frame) override;

    /// The path `requested` resolves to on this driver; throws subscan::Error when Int64 is
    /// forced without 64-bit atomics.
    static RasterPath resolvePath(RasterPath requested, const GlCapabilities& capabilities);

    /// The shader and the defines of every variant that needs 64-bit atomics, for checking
    /// that they compile where the driver cannot run them.
    static std::string_view shaderPath();
    static std::vector<std::string> int64VariantDefines();

    /// The winning point index per pixel of the last frame rendered into `resources`
    /// (0xFFFFFFFF where empty), row 0 at the top: for checking the rasterizer against a CPU
    /// reference.
    std::vector<std::uint32_t> readWinners(const FrameResources& resources) const;

  private:
    /// The stages that sum and resolve the blends (the 32-bit path's sums are its index
    /// stage), compiled on first use.
    struct BlendPrograms {
        Program sums;
        Program resolve;
    };

    void runPerChunk(const Program& program, FrameContext& frame, bool perPixel);
    const BlendPrograms& blendPrograms(bool int64, bool colors, bool normals);

    const ShaderSources& sources_;
    std::array<std::optional<BlendPrograms>, 8> blendPrograms_;  // by int64, colours, normals

    Program depthStage_;
    Program indexStage_;
    Program resolve32_;
    Program int64Stage_;  // only where 64-bit atomics exist
    Program resolve64_;
    UniformBlock<gpu::RasterParams> params_{"RasterizePoints.params"};
    bool lastFrameInt64_ = false;
};

}  // namespace subscan
