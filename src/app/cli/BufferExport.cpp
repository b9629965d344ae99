#include "app/cli/BufferExport.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/format.h>

#include "core/Error.h"
#include "core/Srgb.h"
#include "io/CameraJson.h"
#include "io/Image.h"
#include "render/FrameBuffers.h"

namespace subscan::cli {

namespace {

/// What exportBuffers writes, as it names the files: readFrameBuffers' buffers as color.png,
/// mask.png and NAME.pfm, and the cameras.
constexpr std::string_view kBufferFiles[] = {"camera.json", "buffers_camera.json", "depth.pfm",
                                             "color.png",   "normals.pfm",         "radiance.pfm",
                                             "mask.png",    "single.pfm",          "sigma_s.pfm",
                                             "sigma_a.pfm"};

/// The file `buffer` (a readFrameBuffers name) is written to.
std::string bufferFileName(const std::string& buffer) {
    const std::string name =
        buffer == "color" || buffer == "mask" ? buffer + ".png" : buffer + ".pfm";
    if (!isBufferFile(name)) {
        // Else an earlier export's would stay beside the next one's without a word.
        throw std::logic_error(
            fmt::format("the buffer file {} is missing from kBufferFiles", name));
    }
    return name;
}

}  // namespace

bool isBufferFile(const std::filesystem::path& file) {
    return std::ranges::find(kBufferFiles, file.filename().string()) != std::end(kBufferFiles);
}

Error notAnExport(const std::filesystem::path& entry) {
    return Error(fmt::format(
        "{}: --export-buffers replaces the files of an earlier export in its folder, and this is "
        "none of them; give --export-buffers a new or empty folder",
        entry.string()));
}

void checkExportFolder(const FrameOptions& frame, const std::filesystem::path& directory,
                       const std::function<bool(const std::filesystem::path&)>& alsoWritten) {
    frame.refuseToOverwriteInputs(directory / "camera.json", "the camera");
    frame.refuseToOverwriteInputs(directory / "buffers_camera.json", "the buffers' camera");
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator(directory, error)) {
        if (entry.is_regular_file() && isBufferFile(entry.path())) {
            frame.refuseToOverwriteInputs(entry.path(), "the buffers");
        } else if (!alsoWritten || !alsoWritten(entry.path())) {
            throw notAnExport(entry.path());
        }
    }
}

void removeExport(const std::filesystem::path& directory) {
    for (const std::string_view name : kBufferFiles) {
        removeEarlierOutput(directory / name, "this buffer of an earlier export");
    }
    removeEarlierOutput(directory, "this earlier export");
}

void exportBuffers(const std::filesystem::path& directory, const Renderer& renderer,
                   const RenderSettings& settings, const Camera& picture) {
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error) {
        throw Error(fmt::format("{}: cannot create the directory: {}", directory.string(),
                                error.message()));
    }
    std::vector<std::string> written{"camera.json"};
    writeCameraFile(directory / "camera.json", picture);
    const Camera& buffersCamera = renderer.pipelineCamera();
    if (buffersCamera.width != picture.width || buffersCamera.height != picture.height ||
        buffersCamera.jitterPixels != picture.jitterPixels) {
        written.emplace_back("buffers_camera.json");
        writeCameraFile(directory / written.back(), buffersCamera);
    }
    const std::vector<FrameBuffer> buffers = readFrameBuffers(renderer, settings);
    // "depth" comes first: color.png's alpha and mask.png are where it is finite.
    const ImageF& depth = buffers.front().image;
    for (const auto& [name, image] : buffers) {
        written.push_back(bufferFileName(name));
        const std::filesystem::path file = directory / written.back();
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
            writePng(file, png);
        } else if (name == "mask") {
            Image8 png{image.width, image.height, 1,
                       std::vector<std::uint8_t>(image.values.size())};
            for (std::size_t pixel = 0; pixel < image.values.size(); ++pixel) {
                png.pixels[pixel] = image.values[pixel] > 0.0f ? 255 : 0;
            }
            writePng(file, png);
        } else {
            writePfm(file, image);
        }
    }
    // An earlier export's buffers of another mode or camera would pass for this frame's.
    for (const std::string_view name : kBufferFiles) {
        if (std::ranges::find(written, name) == written.end()) {
            removeEarlierOutput(directory / name, "this buffer of an earlier export");
        }
    }
}

}  // namespace subscan::cli
