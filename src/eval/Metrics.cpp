#include "eval/Metrics.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

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

QualityMetrics compareToGroundTruth(const ReconstructionImages& reconstruction,
                                    const GroundTruthImages& truth, double spacing) {
    std::size_t truthPixels = 0, reconstructed = 0, both = 0, occluded = 0;
    std::vector<double> depthErrors;
    std::vector<double> normalErrors;
    const bool hasNormals = !reconstruction.normals.empty();
    for (std::size_t i = 0; i < truth.depth.size(); ++i) {
        const bool inTruth = std::isfinite(truth.depth[i]);
        const bool inReconstruction = std::isfinite(reconstruction.depth[i]);
        truthPixels += inTruth;
        reconstructed += inReconstruction;
        if (!(inTruth && inReconstruction)) {
            continue;
        }
        ++both;
        const double difference = static_cast<double>(reconstruction.depth[i]) - truth.depth[i];
        depthErrors.push_back(std::abs(difference) / spacing);
        occluded += difference > 3.0 * spacing;
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

}  // namespace subscan
