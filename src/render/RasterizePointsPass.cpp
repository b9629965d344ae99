#include "render/RasterizePointsPass.h"

#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

enum class RasterStage { Depth, Index, Int64, Blend, Resolve };

/// What the blend's sums hold: the colours, the normals, or both.
struct Blended {
    bool colors = false;
    bool normals = false;

    bool any() const { return colors || normals; }
};

std::string stageDefines(RasterStage stage, bool useInt64, Blended blended = {}) {
    return fmt::format(
        "#define STAGE_DEPTH {}\n#define STAGE_INDEX {}\n#define STAGE_INT64 {}\n"
        "#define STAGE_BLEND {}\n#define STAGE_RESOLVE {}\n#define USE_INT64 {}\n"
        "#define BLEND_COLORS {}\n#define BLEND_NORMALS {}\n",
        int(stage == RasterStage::Depth), int(stage == RasterStage::Index),
        int(stage == RasterStage::Int64), int(stage == RasterStage::Blend),
        int(stage == RasterStage::Resolve), int(useInt64), int(blended.colors),
        int(blended.normals));
}

constexpr std::string_view kShader = "render/RasterizePoints.comp";

constexpr std::uint32_t kEmptyIndex = 0xFFFFFFFFu;

}  // namespace

RasterizePointsPass::RasterizePointsPass(const ShaderSources& sources,
                                         const GlCapabilities& capabilities)
    : sources_(sources) {
    depthStage_ = Program::compute(sources, kShader, stageDefines(RasterStage::Depth, false));
    indexStage_ = Program::compute(sources, kShader, stageDefines(RasterStage::Index, false));
    resolve32_ = Program::compute(sources, kShader, stageDefines(RasterStage::Resolve, false));
    if (capabilities.int64Atomics) {
        int64Stage_ = Program::compute(sources, kShader, stageDefines(RasterStage::Int64, true));
        resolve64_ = Program::compute(sources, kShader, stageDefines(RasterStage::Resolve, true));
    }
}

const RasterizePointsPass::BlendPrograms& RasterizePointsPass::blendPrograms(bool int64,
                                                                             bool colors,
                                                                             bool normals) {
    std::optional<BlendPrograms>& programs =
        blendPrograms_[std::size_t(int64) * 4 + std::size_t(colors) * 2 + std::size_t(normals)];
    if (!programs) {
        // The 32-bit path sums in its index stage, which reads the nearest depth anyway.
        const Blended blended{colors, normals};
        const RasterStage sums = int64 ? RasterStage::Blend : RasterStage::Index;
        programs.emplace(
            BlendPrograms{Program::compute(sources_, kShader, stageDefines(sums, int64, blended)),
                          Program::compute(sources_, kShader,
                                           stageDefines(RasterStage::Resolve, int64, blended))});
    }
    return *programs;
}

std::string_view RasterizePointsPass::shaderPath() {
    return kShader;
}

std::vector<std::string> RasterizePointsPass::int64VariantDefines() {
    std::vector<std::string> defines{stageDefines(RasterStage::Int64, true),
                                     stageDefines(RasterStage::Resolve, true)};
    for (const Blended blended :
         {Blended{true, false}, Blended{false, true}, Blended{true, true}}) {
        defines.push_back(stageDefines(RasterStage::Blend, true, blended));
        defines.push_back(stageDefines(RasterStage::Resolve, true, blended));
    }
    return defines;
}

RasterPath RasterizePointsPass::resolvePath(RasterPath requested,
                                            const GlCapabilities& capabilities) {
    if (requested == RasterPath::Int64 && !capabilities.int64Atomics) {
        throw Error(
            fmt::format("the 64-bit rasterizer needs GL_NV_shader_atomic_int64, which {} "
                        "does not offer (use --raster two-pass or auto)",
                        capabilities.renderer));
    }
    if (requested == RasterPath::Auto) {
        return capabilities.int64Atomics ? RasterPath::Int64 : RasterPath::TwoPass32;
    }
    return requested;
}

void RasterizePointsPass::runPerChunk(const Program& program, FrameContext& frame, bool perPixel) {
    program.use();
    const TexelRegion region = frame.cloudRegion();
    if (perPixel) {
        ComputeStages::setRegionUniforms(program, region);
    }
    const std::size_t pixels = static_cast<std::size_t>(frame.camera.width) *
                               static_cast<std::size_t>(frame.camera.height);
    for (const GpuPointCloud::Chunk& chunk : frame.cloud.chunks()) {
        params_.set({chunk.firstPoint, chunk.pointCount, static_cast<std::uint32_t>(pixels),
                     frame.settings.raster.colorBlend,
                     glm::vec4(frame.settings.raster.normalBlend, 0.0f, 0.0f, 0.0f)});
        params_.bind(SUBSCAN_UBO_PASS);
        chunk.positions.bindTexels(SUBSCAN_TEXELS_POSITIONS, TextureFormat::R32F);
        chunk.colors.bindTexels(SUBSCAN_TEXELS_COLORS, TextureFormat::R32UI);
        if (frame.cloud.hasLocalSpacing()) {
            chunk.localSpacing.bindTexels(SUBSCAN_TEXELS_LOCAL_SPACING, TextureFormat::RGBA16F);
        }
        if (usesPointNormals(frame.settings)) {
            chunk.normals.bindTexels(SUBSCAN_TEXELS_POINT_NORMALS, TextureFormat::R32UI);
        }
        if (perPixel) {
            Program::dispatch2D(region.size.x, region.size.y, SUBSCAN_IMAGE_GROUP_SIZE,
                                SUBSCAN_IMAGE_GROUP_SIZE);
        } else {
            Program::dispatch1D(chunk.pointCount, SUBSCAN_POINTS_GROUP_SIZE);
        }
    }
}

std::vector<std::uint32_t> RasterizePointsPass::readWinners(const FrameResources& resources) const {
    if (!lastFrameInt64_) {
        return resources.texture("pointIndex").readUints();
    }
    const std::vector<std::uint64_t> keys = resources.buffer("depthIndex").read<std::uint64_t>();
    std::vector<std::uint32_t> winners(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i) {
        winners[i] = static_cast<std::uint32_t>(keys[i] & 0xFFFFFFFFu);
    }
    return winners;
}

std::vector<std::string_view> RasterizePointsPass::outputs(const RenderSettings& settings) const {
    std::vector<std::string_view> names{"depth", "color"};
    if (placesOutlineBySubpixels(settings)) {
        names.push_back("occupancy");
    }
    if (usesPointNormals(settings)) {
        names.push_back("pointNormals");
    }
    if (settings.surface.localSpacing) {
        names.push_back("acrossLines");
    }
    return names;
}

void RasterizePointsPass::execute(FrameContext& frame) {
    const int width = frame.camera.width;
    const int height = frame.camera.height;
    const bool int64 =
        resolvePath(frame.settings.raster.path, frame.capabilities) == RasterPath::Int64;
    lastFrameInt64_ = int64;
    Texture& depth = frame.resources.ensureTexture("depth", TextureFormat::R32F, width, height);
    Texture& color = frame.resources.ensureTexture("color", TextureFormat::RGBA16F, width, height);

    // Empty pixels: +inf and no colour. The resolve then visits only the pixels the cloud's
    // bounding box projects to, and writes those that hold a point.
    frame.clear(depth, glm::vec4(std::numeric_limits<float>::infinity()));
    frame.clear(color);
    const bool pointNormals = usesPointNormals(frame.settings);
    if (pointNormals && !frame.cloud.hasNormals()) {
        throw Error("the settings ask for the points' normals, but the cloud has none");
    }
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    if (placesOutlineBySubpixels(frame.settings)) {
        // Which 4x4 sub-cells of each pixel hold points (FillRemoval.glsl's outline).
        Buffer& occupancy =
            frame.resources.ensureBuffer("occupancy", pixels * sizeof(std::uint32_t));
        frame.fill(occupancy, 0u);
        occupancy.bindStorage(SUBSCAN_SSBO_OCCUPANCY);
    }
    const Blended blended{frame.settings.raster.colorBlend > 0.0f,
                          pointNormals && frame.settings.raster.normalBlend > 0.0f};
    if (blended.colors) {
        // Every point near its pixel's nearest adds to the pixel's sums; the resolve divides.
        Buffer& sums =
            frame.resources.ensureBuffer("colorSums", pixels * 4 * sizeof(std::uint32_t));
        frame.fill(sums, 0u);
        sums.bindStorage(SUBSCAN_SSBO_COLOR_SUMS);
    }
    if (blended.normals) {
        Buffer& sums =
            frame.resources.ensureBuffer("normalSums", pixels * 3 * sizeof(std::int32_t));
        frame.fill(sums, 0u);
        sums.bindStorage(SUBSCAN_SSBO_NORMAL_SUMS);
    }
    if (int64) {
        Buffer& depthIndex =
            frame.resources.ensureBuffer("depthIndex", pixels * sizeof(std::uint64_t));
        frame.fill(depthIndex, kEmptyIndex);  // both halves all ones: no depth, no point
        depthIndex.bindStorage(SUBSCAN_SSBO_DEPTH_INDEX);
        runPerChunk(int64Stage_, frame, false);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        if (blended.any()) {
            runPerChunk(blendPrograms(true, blended.colors, blended.normals).sums, frame, false);
            glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        }
        depth.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    } else {
        Texture& pointIndex =
            frame.resources.ensureTexture("pointIndex", TextureFormat::R32UI, width, height);
        frame.clearUint(pointIndex, kEmptyIndex);
        depth.bindImageBits(SUBSCAN_IMAGE_OUT0, GL_READ_WRITE);
        runPerChunk(depthStage_, frame, false);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        depth.bindImageBits(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
        pointIndex.bindImage(SUBSCAN_IMAGE_OUT2, GL_READ_WRITE);
        runPerChunk(blended.any() ? blendPrograms(false, blended.colors, blended.normals).sums
                                  : indexStage_,
                    frame, false);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
        pointIndex.bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    }
    color.bindImage(SUBSCAN_IMAGE_OUT1, GL_WRITE_ONLY);
    if (pointNormals) {
        // Read only where a point won its pixel, which the resolve writes: nothing to clear.
        frame.resources.ensureTexture("pointNormals", TextureFormat::RGBA16F, width, height)
            .bindImage(SUBSCAN_IMAGE_OUT2, GL_WRITE_ONLY);
    }
    if (frame.settings.surface.localSpacing) {
        // Read only where a point won its pixel, which the resolve writes: nothing to clear.
        frame.resources.ensureBuffer("acrossLines", pixels * sizeof(std::uint32_t))
            .bindStorage(SUBSCAN_SSBO_ACROSS_LINES);
    }
    runPerChunk(blended.any() ? blendPrograms(int64, blended.colors, blended.normals).resolve
                : int64       ? resolve64_
                              : resolve32_,
                frame, true);
    // The storage bit for the sub-pixel cells, which fill removal reads.
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT |
                    GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                    GL_SHADER_STORAGE_BARRIER_BIT);
}

}  // namespace subscan
