#include "render/FrameBuffers.h"

#include <cmath>

namespace subscan {

namespace {

/// Keeps the first `channels` of the 4 in an RGBA float texture.
ImageF channelsOf(const Texture& texture, int channels) {
    const std::vector<float> rgba = texture.readFloats();
    ImageF image{texture.width(), texture.height(), channels, {}};
    const std::size_t pixels = rgba.size() / 4;
    image.values.reserve(pixels * static_cast<std::size_t>(channels));
    for (std::size_t pixel = 0; pixel < pixels; ++pixel) {
        for (int c = 0; c < channels; ++c) {
            image.values.push_back(rgba[4 * pixel + static_cast<std::size_t>(c)]);
        }
    }
    return image;
}

}  // namespace

std::vector<FrameBuffer> readFrameBuffers(const Renderer& renderer,
                                          const RenderSettings& settings) {
    const RenderMode mode = settings.raster.mode;
    const Camera& camera = renderer.pipelineCamera();
    const FrameResources& resources = renderer.resources();
    const bool surface = reconstructsSurface(mode);
    std::vector<FrameBuffer> buffers;

    ImageF depth{camera.width, camera.height, 1,
                 resources.texture(surface ? "surfaceDepth" : "depth").readFloats()};
    ImageF color = channelsOf(resources.texture(surface ? "filledColor" : "color"), 3);
    for (std::size_t pixel = 0; pixel < depth.values.size(); ++pixel) {
        if (std::isinf(depth.values[pixel])) {  // the fill's colour reaches past the mask
            for (std::size_t c = 0; c < 3; ++c) {
                color.values[3 * pixel + c] = 0.0f;
            }
        }
    }
    ImageF mask{camera.width, camera.height, 1, std::vector<float>(depth.values.size())};
    for (std::size_t pixel = 0; pixel < depth.values.size(); ++pixel) {
        mask.values[pixel] = std::isinf(depth.values[pixel]) ? 0.0f : 1.0f;
    }
    buffers.push_back({"depth", std::move(depth)});
    buffers.push_back({"color", std::move(color)});
    if (!surface) {
        return buffers;
    }
    buffers.push_back({"normals", channelsOf(resources.texture("normals"), 3)});
    const bool scattered = mode == RenderMode::Sss && resources.has("scatteredRadiance");
    buffers.push_back(
        {"radiance",
         channelsOf(resources.texture(scattered ? "scatteredRadiance" : "radiance"), 3)});
    buffers.push_back({"mask", std::move(mask)});
    if (scattered && settings.scattering.method != ScatteringMethod::Gaussian) {
        buffers.push_back({"single", channelsOf(resources.texture("singleScattering"), 3)});
        buffers.push_back({"sigma_s", channelsOf(resources.texture("sigmaSPrime"), 3)});
        buffers.push_back({"sigma_a", channelsOf(resources.texture("sigmaA"), 3)});
    }
    return buffers;
}

}  // namespace subscan
