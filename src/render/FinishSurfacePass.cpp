#include "render/FinishSurfacePass.h"

#include <limits>

#include <fmt/format.h>

#include "core/Error.h"
#include "render/ComputeStages.h"
#include "render/PresentPass.h"
#include "render/ShadePass.h"
#include "render/TemporalPass.h"

namespace subscan {

namespace {

// FINISH_OUTPUT in FinishSurface.comp.
constexpr int kFinishPicture = 0;
constexpr int kFinishRadianceAndDepth = 1;
constexpr int kFinishRestart = 2;  // then still: TemporalHistory::Mode in order

}  // namespace

FinishSurfacePass::FinishSurfacePass(const ShaderSources& sources, Output output,
                                     TemporalHistory* history)
    : sources_(sources), output_(output), history_(history) {
    if (output == Output::Temporal && !history) {
        throw Error("FinishSurface's temporal filter needs the filter's history");
    }
}

std::vector<std::string_view> FinishSurfacePass::inputs(const RenderSettings& settings) const {
    std::vector<std::string_view> names{"pullValues", "pullWeights", "pushValues", "normalPyramid"};
    if (followsNormalsToOutline(settings)) {
        names.insert(names.end(), {"surfaceDepth", "mask"});  // FillRemovalPass's
        return names;
    }
    names.insert(names.end(), {"fillReach", "fillSparse"});
    if (placesOutlineBySubpixels(settings)) {
        names.push_back("occupancy");
    }
    return names;
}

std::vector<std::string_view> FinishSurfacePass::outputs(const RenderSettings& settings) const {
    std::vector<std::string_view> names;
    switch (output_) {
        case Output::Picture:
            names = {"image"};
            break;
        case Output::RadianceAndDepth:
            names = {"radianceAndDepth"};
            break;
        case Output::Temporal:
            names = {"image", "history", "historyState"};
            break;
    }
    if (!followsNormalsToOutline(settings)) {
        names.push_back("surfaceDepth");
    }
    return names;
}

const Program& FinishSurfacePass::program(const Variant& variant) {
    auto found = programs_.find(variant);
    if (found == programs_.end()) {
        const auto [directionalLights, finishOutput, seesOutline] = variant;
        const std::string defines = fmt::format(
            "#define SHADE_DIRECTIONAL_LIGHTS {}\n#define FINISH_OUTPUT {}\n"
            "#define FINISH_SEES_OUTLINE {}\n",
            directionalLights ? 1 : 0, finishOutput, seesOutline ? 1 : 0);
        found =
            programs_
                .emplace(variant, Program::compute(sources_, "render/FinishSurface.comp", defines))
                .first;
    }
    return found->second;
}

void FinishSurfacePass::execute(FrameContext& frame) {
    if (!canFinish(frame.divisor, frame.pyramid)) {
        throw Error("FinishSurface needs a full-resolution frame of more than one pixel");
    }
    FrameResources& resources = frame.resources;
    resources.buffer("pullValues").bindTexels(SUBSCAN_TEXELS_PULL_VALUES, TextureFormat::RGBA32F);
    resources.buffer("pullWeights").bindTexels(SUBSCAN_TEXELS_PULL_WEIGHTS, TextureFormat::RG32F);
    resources.buffer("pushValues").bindTexels(SUBSCAN_TEXELS_PUSH_VALUES, TextureFormat::RGBA32F);
    resources.buffer("normalPyramid").bindTexels(SUBSCAN_TEXELS_NORMALS, TextureFormat::RGBA32F);
    const bool seesOutline = followsNormalsToOutline(frame.settings);
    if (seesOutline) {
        resources.texture("surfaceDepth").bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
        resources.texture("mask").bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    } else {
        resources.buffer("fillReach").bindTexels(SUBSCAN_TEXELS_FILL_REACH, TextureFormat::R32UI);
        resources.buffer("fillSparse").bindTexels(SUBSCAN_TEXELS_FILL_SPARSE, TextureFormat::R32UI);
        if (placesOutlineBySubpixels(frame.settings)) {
            resources.buffer("occupancy").bindStorage(SUBSCAN_SSBO_OCCUPANCY);
        }
        frame
            .imageOverRegion("surfaceDepth", TextureFormat::R32F,
                             glm::vec4(std::numeric_limits<float>::infinity()))
            .bindImage(SUBSCAN_IMAGE_OUT1, GL_WRITE_ONLY);
    }
    const gpu::ShadeParams shade = ShadePass::parameters(frame);
    params_.set(shade);
    params_.bind(SUBSCAN_UBO_PASS);

    int finishOutput = kFinishPicture;
    TemporalHistory::Mode mode = TemporalHistory::Mode::Restart;
    if (output_ == Output::Temporal) {
        // Before begin(), which swaps and clears the history for a frame that must then end.
        if (history_->modeFor(frame.camera, frame.settings, frame.divisor) ==
            TemporalHistory::Mode::Moving) {
            throw Error("FinishSurface blends a moving camera's frame only in TemporalPass");
        }
        // Binds the picture too, cleared to the background off the region.
        mode = history_->begin(frame, true);
        finishOutput = kFinishRestart + static_cast<int>(mode);
    } else {
        const bool picture = output_ == Output::Picture;
        Texture* color = nullptr;
        if (picture) {
            color = &resources.ensureTexture("image", TextureFormat::RGBA8, frame.width(),
                                             frame.height());
            if (frame.restricted()) {
                PresentPass::clearToBackground(frame, *color);
            }
        } else {
            // TemporalPass reads the pixels next to the region too: there they are background.
            color = &frame.imageOverRegion(
                "radianceAndDepth", TextureFormat::RGBA32F, 1,
                glm::vec4(0.0f, 0.0f, 0.0f, std::numeric_limits<float>::infinity()));
        }
        color->bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
        finishOutput = picture ? kFinishPicture : kFinishRadianceAndDepth;
    }
    const Program& shader = program({shade.lightCount.x > 0, finishOutput, seesOutline});
    shader.use();
    const TexelRegion region = frame.region(0);
    ComputeStages::setRegionUniforms(shader, region);
    Program::dispatch2D(region.size.x, region.size.y, SUBSCAN_IMAGE_GROUP_SIZE,
                        SUBSCAN_IMAGE_GROUP_SIZE);
    glMemoryBarrier(kImageWritesBarrier);
    if (output_ == Output::Temporal) {
        history_->end(frame, mode);
    }
}

}  // namespace subscan
