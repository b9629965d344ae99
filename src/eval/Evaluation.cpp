#include "eval/Evaluation.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include <fmt/format.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include "eval/GroundTruth.h"
#include "gpu/ShaderSources.h"
#include "io/Image.h"
#include "render/FrameUniforms.h"
#include "render/PresentPass.h"
#include "render/ReducedResolution.h"
#include "render/Renderer.h"
#include "render/ShadePass.h"

namespace subscan {

namespace {

/// Runs the pipeline's own Shade and Present passes on images that did not come from it (the
/// ground truth, the flat-shaded baselines), so every method is lit by the same code.
class ImageShader {
  public:
    ImageShader(GlContext& context, const GpuPointCloud& cloud)
        : context_(context),
          cloud_(cloud),
          shade_(sources_, ShadeOutputs::Radiance),
          present_(sources_, "radiance", "surfaceDepth") {}

    std::vector<std::uint8_t> shade(const Camera& camera, const RenderSettings& settings,
                                    const std::vector<float>& depth,
                                    const std::vector<glm::vec3>& normals,
                                    const std::vector<glm::vec3>& albedo) {
        const gpu::PyramidLayout& layout = uniforms_.update(camera, settings, 1.0, cloud_.origin());
        const int w = camera.width, h = camera.height;
        std::vector<float> rgba(depth.size() * 4);
        auto upload = [&](const char* name, const std::vector<glm::vec3>& values) {
            for (std::size_t i = 0; i < values.size(); ++i) {
                rgba[4 * i] = values[i].x;
                rgba[4 * i + 1] = values[i].y;
                rgba[4 * i + 2] = values[i].z;
                rgba[4 * i + 3] = 1.0f;
            }
            resources_.ensureTexture(name, TextureFormat::RGBA16F, w, h).uploadFloats(rgba);
        };
        resources_.ensureTexture("surfaceDepth", TextureFormat::R32F, w, h).uploadFloats(depth);
        upload("normals", normals);
        upload("filledColor", albedo);
        FrameContext frame{camera,     cloud_, settings, context_.capabilities(),
                           resources_, layout, 1.0};
        shade_.execute(frame);
        present_.execute(frame);
        return resources_.texture("image").readRgba8();
    }

  private:
    GlContext& context_;
    const GpuPointCloud& cloud_;
    ShaderSources sources_;
    FrameUniforms uniforms_;
    FrameResources resources_;
    ShadePass shade_;
    PresentPass present_;
};

std::vector<glm::vec3> rgbOf(const std::vector<float>& rgba) {
    std::vector<glm::vec3> rgb(rgba.size() / 4);
    for (std::size_t i = 0; i < rgb.size(); ++i) {
        rgb[i] = {rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2]};
    }
    return rgb;
}

/// A pipeline image of `channels` floats per texel at the output camera's pixels: each takes
/// the texel its centre falls in (ReducedResolution.h), as the metrics compare pixel by pixel.
std::vector<float> atOutputPixels(const std::vector<float>& values, int channels,
                                  const Camera& output, const Camera& pipeline, int divisor) {
    if (divisor == 1) {
        return values;
    }
    std::vector<float> resampled;
    resampled.reserve(static_cast<std::size_t>(output.width * output.height * channels));
    for (int y = 0; y < output.height; ++y) {
        for (int x = 0; x < output.width; ++x) {
            const glm::ivec2 texel =
                glm::clamp(glm::ivec2(glm::floor(reducedPosition(output, pipeline, divisor,
                                                                 glm::dvec2(x + 0.5, y + 0.5)))),
                           glm::ivec2(0), glm::ivec2(pipeline.width - 1, pipeline.height - 1));
            const auto first = values.begin() + (texel.y * pipeline.width + texel.x) * channels;
            resampled.insert(resampled.end(), first, first + channels);
        }
    }
    return resampled;
}

/// Normals that face the eye, for flat shading of methods without normals.
std::vector<glm::vec3> towardsEye(const Camera& camera) {
    std::vector<glm::vec3> normals(static_cast<std::size_t>(camera.width * camera.height));
    const double focal = camera.focalLengthPixels();
    for (int y = 0; y < camera.height; ++y) {
        for (int x = 0; x < camera.width; ++x) {
            const glm::dvec3 direction((x + 0.5 - 0.5 * camera.width) / focal,
                                       (0.5 * camera.height - (y + 0.5)) / focal, -1.0);
            normals[static_cast<std::size_t>(y * camera.width + x)] =
                glm::vec3(-glm::normalize(direction));
        }
    }
    return normals;
}

/// The per-view pictures of EvaluationSettings::exportDirectory.
void exportView(const std::filesystem::path& directory, int view, const Camera& camera,
                double spacing, const GroundTruthImages& truth, const ReconstructionImages& surface,
                const std::vector<std::uint8_t>& truthImage,
                const std::vector<std::uint8_t>& surfaceImage) {
    std::filesystem::create_directories(directory);
    const int w = camera.width, h = camera.height;
    const auto name = [&](const char* what) {
        return directory / fmt::format("view{}_{}.png", view, what);
    };
    writePng(name("truth"), {w, h, 4, truthImage});
    writePng(name("surface"), {w, h, 4, surfaceImage});
    Image8 coverage{w, h, 3, std::vector<std::uint8_t>(static_cast<std::size_t>(w * h * 3), 0)};
    Image8 normalError{w, h, 1, std::vector<std::uint8_t>(static_cast<std::size_t>(w * h), 0)};
    for (std::size_t i = 0; i < truth.depth.size(); ++i) {
        const bool inTruth = std::isfinite(truth.depth[i]);
        const bool inSurface = std::isfinite(surface.depth[i]);
        const bool occluded =
            inTruth && inSurface && surface.depth[i] - truth.depth[i] > 3.0 * spacing;
        const glm::u8vec3 color = occluded               ? glm::u8vec3(250, 220, 30)
                                  : inTruth && inSurface ? glm::u8vec3(160)
                                  : inTruth              ? glm::u8vec3(230, 40, 40)
                                  : inSurface            ? glm::u8vec3(40, 80, 230)
                                                         : glm::u8vec3(0);
        for (int c = 0; c < 3; ++c) {
            coverage.pixels[3 * i + static_cast<std::size_t>(c)] = color[c];
        }
        if (inTruth && inSurface) {
            const double cosine = std::clamp(
                static_cast<double>(glm::dot(glm::normalize(surface.normals[i]), truth.normals[i])),
                -1.0, 1.0);
            const double degrees = std::acos(cosine) * 180.0 / std::numbers::pi;
            normalError.pixels[i] =
                static_cast<std::uint8_t>(std::lround(std::min(degrees, 45.0) / 45.0 * 255.0));
        }
    }
    writePng(name("coverage"), coverage);
    writePng(name("normal_error"), normalError);
}

}  // namespace

EvaluationReport evaluate(GlContext& context, const Scene& truth, const PointCloud& points,
                          const EvaluationSettings& settings, const RenderSettings& render) {
    Renderer renderer(context, points);
    ImageShader shader(context, renderer.gpuCloud());
    const double h = renderer.spacing();

    EvaluationReport report;
    std::vector<QualityMetrics> pointViews, surfaceViews;
    std::vector<std::vector<QualityMetrics>> splatViews(
        static_cast<std::size_t>(settings.largestSplat - settings.smallestSplat + 1));
    for (int view = 0; view < settings.views; ++view) {
        OrbitView orbit;
        orbit.yawDegrees = 20.0 + 360.0 * view / settings.views;
        orbit.pitchDegrees = view % 2 == 0 ? 25.0 : -15.0;
        orbit.distance = settings.distance;
        const Camera camera = orbitCamera(truth.bounds(), orbit, settings.width, settings.height,
                                          settings.fovyDegrees);
        const GroundTruthImages groundTruth = renderGroundTruth(truth, camera);
        const std::vector<std::uint8_t> truthImage = shader.shade(
            camera, render, groundTruth.depth, groundTruth.normals, groundTruth.albedo);
        const std::vector<glm::vec3> flatNormals = towardsEye(camera);

        // The baselines: rasterized points, flat shaded.
        auto baseline = [&](RenderMode mode, float pointSize) {
            RenderSettings baselineSettings = render;
            baselineSettings.raster.mode = mode;
            baselineSettings.raster.stage = Stage::Final;
            baselineSettings.raster.pointSize = pointSize;
            renderer.render(camera, baselineSettings);
            ReconstructionImages images{renderer.resources().texture("depth").readFloats(), {}};
            QualityMetrics metrics = compareToGroundTruth(images, groundTruth, h);
            const std::vector<glm::vec3> albedo =
                rgbOf(renderer.resources().texture("color").readFloats());
            metrics.psnrDb =
                psnr(shader.shade(camera, render, images.depth, flatNormals, albedo), truthImage);
            return metrics;
        };
        pointViews.push_back(baseline(RenderMode::Points, 1.0f));
        for (int size = settings.smallestSplat; size <= settings.largestSplat; ++size) {
            splatViews[static_cast<std::size_t>(size - settings.smallestSplat)].push_back(
                baseline(RenderMode::Splats, static_cast<float>(size)));
        }

        RenderSettings surfaceSettings = render;
        surfaceSettings.raster.mode = RenderMode::Surface;
        surfaceSettings.raster.stage = Stage::Final;
        const int divisor =
            renderer.render(camera, surfaceSettings, FrameOutputs::Everything).divisor;
        report.surfaceReducedViews += divisor == 1 ? 0 : 1;
        auto atPixels = [&](const char* name, int channels) {
            return atOutputPixels(renderer.resources().texture(name).readFloats(), channels, camera,
                                  renderer.pipelineCamera(), divisor);
        };
        ReconstructionImages images{atPixels("surfaceDepth", 1), rgbOf(atPixels("normals", 4))};
        QualityMetrics metrics = compareToGroundTruth(images, groundTruth, h);
        const std::vector<std::uint8_t> surfaceImage = renderer.readImage();
        metrics.psnrDb = psnr(surfaceImage, truthImage);
        surfaceViews.push_back(metrics);
        if (!settings.exportDirectory.empty()) {
            exportView(settings.exportDirectory, view, camera, h, groundTruth, images, truthImage,
                       surfaceImage);
        }
    }

    report.views = settings.views;
    report.width = settings.width;
    report.height = settings.height;
    report.points = points.size();
    report.spacing = h;
    report.points1px = average(pointViews);
    report.surface = average(surfaceViews);
    for (std::size_t i = 0; i < splatViews.size(); ++i) {
        const QualityMetrics candidate = average(splatViews[i]);
        if (report.splatSize == 0 || candidate.psnrDb > report.splats.psnrDb) {
            report.splats = candidate;
            report.splatSize = settings.smallestSplat + static_cast<int>(i);
        }
    }
    return report;
}

nlohmann::json toJson(const EvaluationReport& report) {
    auto method = [](const QualityMetrics& m) {
        nlohmann::json json = {
            {"coverage", m.coverage},
            {"leakage", m.leakage},
            {"depth_error_median_h", m.depthErrorMedianH},
            {"occlusion_error_rate", m.occlusionErrorRate},
            {"normal_error_mean_deg", nullptr},
            {"normal_error_p95_deg", nullptr},
            {"psnr_db", m.psnrDb},
        };
        if (m.normalErrorMeanDeg) {
            json["normal_error_mean_deg"] = *m.normalErrorMeanDeg;
            json["normal_error_p95_deg"] = *m.normalErrorP95Deg;
        }
        return json;
    };
    nlohmann::json splats = method(report.splats);
    splats["point_size"] = report.splatSize;
    return {
        {"views", report.views},
        {"width", report.width},
        {"height", report.height},
        {"points", report.points},
        {"spacing", report.spacing},
        {"surface_reduced_views", report.surfaceReducedViews},
        {"methods",
         {{"points", method(report.points1px)},
          {"splats", splats},
          {"surface", method(report.surface)}}},
    };
}

}  // namespace subscan
