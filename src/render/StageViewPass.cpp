#include "render/StageViewPass.h"

#include <algorithm>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

std::string stageMacro(Stage stage) {
    std::string name = toString(stage);
    std::transform(name.begin(), name.end(), name.begin(), ::toupper);
    return name;
}

}  // namespace

StageViewPass::StageViewPass(const ShaderSources& sources, Stage stage)
    : stage_(stage), stages_(sources, "render/StageView.comp", {stageMacro(stage)}) {
    if (isFinalImage(stage)) {
        throw Error(
            fmt::format("the stage '{}' is a final image, not a stage view", toString(stage)));
    }
}

std::vector<std::string_view> StageViewPass::inputs(const RenderSettings&) const {
    switch (stage_) {
        case Stage::Depth:
            return {"depth"};
        case Stage::Pyramid:
            return {"pyramid"};
        case Stage::Visibility:
            return {"depth", "color", "visibility"};
        case Stage::Pull:
            return {"pullValues", "pullWeights"};
        case Stage::Push:
            return {"filledColor"};
        case Stage::Fill:
            return {"filledColor", "mask"};
        case Stage::Normals:
            return {"normals"};
        case Stage::Final:
        case Stage::Shaded:
            break;
    }
    return {};
}

void StageViewPass::execute(FrameContext& frame) {
    FrameResources& resources = frame.resources;
    Texture& output =
        resources.ensureTexture("stage", TextureFormat::RGBA16F, frame.width(), frame.height());
    output.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    auto bindImage = [&](std::string_view name, GLuint unit) {
        resources.texture(name).bindImage(unit, GL_READ_ONLY);
    };
    switch (stage_) {
        case Stage::Depth:
            bindImage("depth", SUBSCAN_IMAGE_IN0);
            break;
        case Stage::Pyramid:
            resources.buffer("pyramid").bindStorage(SUBSCAN_SSBO_PYRAMID);
            break;
        case Stage::Visibility:
            bindImage("depth", SUBSCAN_IMAGE_IN0);
            bindImage("color", SUBSCAN_IMAGE_IN1);
            bindImage("visibility", SUBSCAN_IMAGE_IN2);
            break;
        case Stage::Pull:
            resources.buffer("pullValues").bindStorage(SUBSCAN_SSBO_PULL_VALUES);
            resources.buffer("pullWeights").bindStorage(SUBSCAN_SSBO_PULL_WEIGHTS);
            break;
        case Stage::Push:
            bindImage("filledColor", SUBSCAN_IMAGE_IN1);
            break;
        case Stage::Fill:
            bindImage("filledColor", SUBSCAN_IMAGE_IN1);
            bindImage("mask", SUBSCAN_IMAGE_IN2);
            break;
        case Stage::Normals:
            bindImage("normals", SUBSCAN_IMAGE_IN1);
            break;
        case Stage::Final:
        case Stage::Shaded:
            break;
    }
    const unsigned level = static_cast<unsigned>(std::clamp(
        frame.settings.raster.stageLevel, 0, static_cast<int>(frame.pyramid.info.x) - 1));
    stages_.runOverImage(0, frame.width(), frame.height(), level);
    glMemoryBarrier(kImageWritesBarrier);
}

}  // namespace subscan
