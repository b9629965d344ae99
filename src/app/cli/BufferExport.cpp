#include "app/cli/BufferExport.h"

#include <cmath>
#include <system_error>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/Srgb.h"
#include "io/CameraJson.h"
#include "io/Image.h"
#include "render/FrameBuffers.h"

namespace subscan::cli {

void refuseToOverwriteCameraInputs(const FrameOptions& frame,
                                   const std::filesystem::path& directory) {
    frame.refuseToOverwriteInputs(directory / "camera.json", "the camera");
    frame.refuseToOverwriteInputs(directory / "buffers_camera.json", "the buffers' camera");
}

void exportBuffers(const std::filesystem::path& directory, const Renderer& renderer,
                   const RenderSettings& settings, const Camera& picture) {
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error) {
        throw Error(fmt::format("{}: cannot create the directory: {}", directory.string(),
                                error.message()));
    }
    writeCameraFile(directory / "camera.json", picture);
    const Camera& buffersCamera = renderer.pipelineCamera();
    const std::filesystem::path buffersCameraFile = directory / "buffers_camera.json";
    if (buffersCamera.width != picture.width || buffersCamera.height != picture.height ||
        buffersCamera.jitterPixels != picture.jitterPixels) {
        writeCameraFile(buffersCameraFile, buffersCamera);
    } else {
        // An earlier export's into the same folder would describe other buffers.
        std::filesystem::remove(buffersCameraFile, error);
        if (error) {
            throw Error(fmt::format("{}: cannot remove it: {}", buffersCameraFile.string(),
                                    error.message()));
        }
    }
    const std::vector<FrameBuffer> buffers = readFrameBuffers(renderer, settings);
    // "depth" comes first: color.png's alpha and mask.png are where it is finite.
    const ImageF& depth = buffers.front().image;
    for (const auto& [name, image] : buffers) {
        if (name == "color") {
            // The point (or filled) colour, sRGB, alpha 0 where nothing is.
            Image8 png{image.width, image.height, 4,
                       std::vector<std::uint8_t>(depth.values.size() * 4)};
            for (std::size_t pixel = 0; pixel < depth.values.size(); ++pixel) {
                for (std::size_t c = 0; c < 3; ++c) {
                    png.pixels[4 * pixel + c] = srgb8Channel(image.values[3 * pixel + c]);
                }
                png.pixels[4 * pixel + 3] = std::isinf(depth.values[pixel]) ? 0 : 255;
            }
            writePng(directory / "color.png", png);
        } else if (name == "mask") {
            Image8 png{image.width, image.height, 1,
                       std::vector<std::uint8_t>(image.values.size())};
            for (std::size_t pixel = 0; pixel < image.values.size(); ++pixel) {
                png.pixels[pixel] = image.values[pixel] > 0.0f ? 255 : 0;
            }
            writePng(directory / "mask.png", png);
        } else {
            writePfm(directory / (name + ".pfm"), image);
        }
    }
}

}  // namespace subscan::cli
