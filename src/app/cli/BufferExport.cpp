#include "app/cli/BufferExport.h"

#include <cmath>
#include <system_error>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/Srgb.h"
#include "io/CameraJson.h"
#include "io/Image.h"

namespace subscan::cli {

namespace {

/// Keeps `channels` of the 4 in an RGBA float image (for PFM, which holds 1 or 3).
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

void exportBuffers(const std::filesystem::path& directory, const Renderer& renderer,
                   const RenderSettings& settings) {
    const RenderMode mode = settings.raster.mode;
    const Camera& camera = renderer.pipelineCamera();
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error) {
        throw Error(fmt::format("{}: cannot create the directory: {}", directory.string(),
                                error.message()));
    }
    const FrameResources& resources = renderer.resources();
    const bool surface = reconstructsSurface(mode);
    writeCameraFile(directory / "camera.json", camera);
    const Texture& depthTexture = resources.texture(surface ? "surfaceDepth" : "depth");
    const std::vector<float> depth = depthTexture.readFloats();
    writePfm(directory / "depth.pfm", {camera.width, camera.height, 1, depth});

    // color.png: the point (or filled) colour, sRGB, alpha 0 where nothing is.
    const std::vector<float> color =
        resources.texture(surface ? "filledColor" : "color").readFloats();
    Image8 png{camera.width, camera.height, 4, std::vector<std::uint8_t>(color.size())};
    for (std::size_t pixel = 0; pixel < depth.size(); ++pixel) {
        const bool empty = std::isinf(depth[pixel]);  // the fill's colour reaches past the mask
        for (std::size_t c = 0; c < 3; ++c) {
            png.pixels[4 * pixel + c] = empty ? 0 : srgb8Channel(color[4 * pixel + c]);
        }
        png.pixels[4 * pixel + 3] = empty ? 0 : 255;
    }
    writePng(directory / "color.png", png);
    if (!surface) {
        return;
    }
    writePfm(directory / "normals.pfm", channelsOf(resources.texture("normals"), 3));
    const bool scattered = mode == RenderMode::Sss && resources.has("scatteredRadiance");
    writePfm(directory / "radiance.pfm",
             channelsOf(resources.texture(scattered ? "scatteredRadiance" : "radiance"), 3));
    Image8 mask{camera.width, camera.height, 1, std::vector<std::uint8_t>(depth.size())};
    for (std::size_t pixel = 0; pixel < depth.size(); ++pixel) {
        mask.pixels[pixel] = std::isinf(depth[pixel]) ? 0 : 255;
    }
    writePng(directory / "mask.png", mask);
    if (scattered && settings.scattering.method != ScatteringMethod::Gaussian) {
        writePfm(directory / "single.pfm", channelsOf(resources.texture("singleScattering"), 3));
        writePfm(directory / "sigma_s.pfm", channelsOf(resources.texture("sigmaSPrime"), 3));
        writePfm(directory / "sigma_a.pfm", channelsOf(resources.texture("sigmaA"), 3));
    }
}

}  // namespace subscan::cli
