#include "eval/Metrics.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "core/Srgb.h"

namespace subscan {

namespace {

double percentile(std::vector<double>& values, double fraction) {
    if (values.empty()) {
        return 0.0;
    }
    const auto index =
        static_cast<std::size_t>(fraction * static_cast<double>(values.size() - 1) + 0.5);
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(index),
                     values.end());
    return values[index];
}

}  // namespace

bool showsThrough(const GroundTruthImages& truth, std::size_t i, float reconstructedDepth,
                  double h) {
    const double scale = truth.spacing.empty() ? h : std::max(h, double{truth.spacing[i]});
    const double withinPixel =
        truth.depthWithinPixel.empty() ? 0.0 : double{truth.depthWithinPixel[i]};
    return static_cast<double>(reconstructedDepth) - truth.depth[i] > 3.0 * scale + withinPixel;
}

QualityMetrics compareToGroundTruth(const ReconstructionImages& reconstruction,
                                    const GroundTruthImages& truth, double spacing) {
    std::size_t truthPixels = 0, reconstructed = 0, both = 0, occluded = 0;
    std::vector<double> depthErrors;
    std::vector<double> signedDepthErrors;
    std::vector<double> normalErrors;
    const bool hasNormals = !reconstruction.normals.empty();
    const bool masked = !truth.sampled.empty();
    for (std::size_t i = 0; i < truth.depth.size(); ++i) {
        const bool inTruth = std::isfinite(truth.depth[i]);
        // A true surface the scan could not sample is neither to be covered nor leaked onto.
        if (inTruth && masked && truth.sampled[i] == 0) {
            continue;
        }
        const bool inReconstruction = std::isfinite(reconstruction.depth[i]);
        truthPixels += inTruth;
        reconstructed += inReconstruction;
        if (!(inTruth && inReconstruction)) {
            continue;
        }
        ++both;
        const double difference = static_cast<double>(reconstruction.depth[i]) - truth.depth[i];
        depthErrors.push_back(std::abs(difference) / spacing);
        signedDepthErrors.push_back(difference / spacing);
        occluded += showsThrough(truth, i, reconstruction.depth[i], spacing);
        if (hasNormals) {
            const double cosine =
                std::clamp(static_cast<double>(glm::dot(glm::normalize(reconstruction.normals[i]),
                                                        truth.normals[i])),
                           -1.0, 1.0);
            normalErrors.push_back(std::acos(cosine) * 180.0 / std::numbers::pi);
        }
    }
    QualityMetrics metrics;
    metrics.coverage =
        truthPixels ? static_cast<double>(both) / static_cast<double>(truthPixels) : 0.0;
    metrics.leakage = reconstructed ? static_cast<double>(reconstructed - both) /
                                          static_cast<double>(reconstructed)
                                    : 0.0;
    metrics.depthErrorMedianH = percentile(depthErrors, 0.5);
    metrics.depthBiasH = percentile(signedDepthErrors, 0.5);
    metrics.occlusionErrorRate =
        both ? static_cast<double>(occluded) / static_cast<double>(both) : 0.0;
    if (hasNormals) {
        double sum = 0.0;
        for (const double error : normalErrors) {
            sum += error;
        }
        metrics.normalErrorMeanDeg =
            normalErrors.empty() ? 0.0 : sum / static_cast<double>(normalErrors.size());
        metrics.normalErrorP95Deg = percentile(normalErrors, 0.95);
    }
    return metrics;
}

double psnr(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    double squared = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
        if (i % 4 == 3) {
            continue;  // alpha
        }
        const double difference = static_cast<double>(a[i]) - static_cast<double>(b[i]);
        squared += difference * difference;
        ++count;
    }
    if (count == 0 || squared == 0.0) {
        return 100.0;
    }
    const double mse = squared / static_cast<double>(count);
    return std::min(100.0, 10.0 * std::log10(255.0 * 255.0 / mse));
}

QualityMetrics average(const std::vector<QualityMetrics>& views) {
    QualityMetrics mean;
    if (views.empty()) {
        return mean;
    }
    const auto n = static_cast<double>(views.size());
    double normalMean = 0.0, normalP95 = 0.0;
    bool hasNormals = true;
    for (const QualityMetrics& view : views) {
        mean.coverage += view.coverage / n;
        mean.leakage += view.leakage / n;
        mean.depthErrorMedianH += view.depthErrorMedianH / n;
        mean.depthBiasH += view.depthBiasH / n;
        mean.occlusionErrorRate += view.occlusionErrorRate / n;
        mean.psnrDb += view.psnrDb / n;
        hasNormals = hasNormals && view.normalErrorMeanDeg.has_value();
        if (hasNormals) {
            normalMean += *view.normalErrorMeanDeg / n;
            normalP95 += *view.normalErrorP95Deg / n;
        }
    }
    if (hasNormals) {
        mean.normalErrorMeanDeg = normalMean;
        mean.normalErrorP95Deg = normalP95;
    }
    return mean;
}

TemporalMetrics compareSequences(const std::vector<SequenceFrame>& frames,
                                 const std::vector<SequenceFrame>& truth) {
    if (frames.size() != truth.size()) {
        throw std::invalid_argument("the sequences differ in length");
    }
    TemporalMetrics metrics;
    if (frames.empty()) {
        return metrics;
    }
    for (std::size_t t = 0; t < frames.size(); ++t) {
        if (frames[t].image.size() != truth[t].image.size() ||
            frames[t].mask.size() != truth[t].mask.size() ||
            frames[t].image.size() != 4 * frames[t].mask.size()) {
            throw std::invalid_argument("the sequences' frames differ in size");
        }
        metrics.psnrDb += psnr(frames[t].image, truth[t].image) / frames.size();
    }
    if (frames.size() < 2) {
        return metrics;
    }
    const double steps = static_cast<double>(frames.size() - 1);
    for (std::size_t t = 1; t < frames.size(); ++t) {
        const SequenceFrame &now = frames[t], &before = frames[t - 1];
        const SequenceFrame &truthNow = truth[t], &truthBefore = truth[t - 1];
        double error = 0.0;
        std::size_t flicker = 0;
        for (std::size_t i = 0; i < now.mask.size(); ++i) {
            for (std::size_t c = 0; c < 3; ++c) {
                const std::size_t k = 4 * i + c;
                const int change = int(now.image[k]) - int(before.image[k]);
                const int truthChange = int(truthNow.image[k]) - int(truthBefore.image[k]);
                error += std::abs(change - truthChange) / 255.0;
            }
            const bool flipped = now.mask[i] != before.mask[i];
            const bool truthFlipped = truthNow.mask[i] != truthBefore.mask[i];
            flicker += flipped != truthFlipped ? 1 : 0;
        }
        const double pixels = static_cast<double>(now.mask.size());
        metrics.temporalError += error / (3.0 * pixels) / steps;
        metrics.maskFlicker += static_cast<double>(flicker) / pixels / steps;
    }
    return metrics;
}

std::vector<std::uint8_t> downsampleSrgb(const std::vector<std::uint8_t>& image, int width,
                                         int height, int factor) {
    const int fineWidth = width * factor;
    std::vector<std::uint8_t> result(static_cast<std::size_t>(width * height * 4), 255);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            for (int c = 0; c < 3; ++c) {
                double sum = 0.0;
                for (int sy = 0; sy < factor; ++sy) {
                    for (int sx = 0; sx < factor; ++sx) {
                        const std::size_t k =
                            4 * static_cast<std::size_t>((y * factor + sy) * fineWidth +
                                                         x * factor + sx) +
                            static_cast<std::size_t>(c);
                        sum += srgbToLinear(image[k] / 255.0f);
                    }
                }
                result[4 * static_cast<std::size_t>(y * width + x) + static_cast<std::size_t>(c)] =
                    srgb8Channel(static_cast<float>(sum / (factor * factor)));
            }
        }
    }
    return result;
}

}  // namespace subscan
