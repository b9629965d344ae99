#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "eval/GroundTruth.h"

namespace subscan {

/// A method's per-pixel result for one view (rows top first): depth +inf where it shows nothing;
/// normals empty when the method has none (1-pixel points, splats).
struct ReconstructionImages {
    std::vector<float> depth;
    std::vector<glm::vec3> normals;
};

/// The quality metrics of DESIGN.md §7 for one view, or averaged over views.
struct QualityMetrics {
    double coverage = 0.0;            // |rec ∩ gt| / |gt|
    double leakage = 0.0;             // |rec \ gt| / |rec|
    double depthErrorMedianH = 0.0;   // median |z_rec - z_gt| / h over rec ∩ gt
    double depthBiasH = 0.0;          // median (z_rec - z_gt) / h over rec ∩ gt: < 0 in front
    double occlusionErrorRate = 0.0;  // share of rec ∩ gt that showsThrough: z_rec - z_gt > 3 h
                                      // (see there for the spacing and the pixel's depths)
    std::optional<double> normalErrorMeanDeg;
    std::optional<double> normalErrorP95Deg;
    double psnrDb = 0.0;  // shaded image against the shaded ground truth, 8-bit sRGB
};

/// Whether a reconstructed depth at pixel `i` of `truth` lies so far behind the true surface
/// that a surface behind it shows through: more than 3 h behind, or 3 times the scan's spacing
/// there where `truth` gives it (GroundTruthImages::spacing), and never less than 3 h, beyond
/// the depths the true surface takes within the pixel (GroundTruthImages::depthWithinPixel,
/// where given): the truth is the pixel centre's, a point anywhere in the pixel.
bool showsThrough(const GroundTruthImages& truth, std::size_t i, float reconstructedDepth,
                  double h);

/// Everything but PSNR, from the images; `spacing` is h. Pixels whose true surface the scan
/// could not sample (GroundTruthImages::sampled) count nowhere: coverage is over the sampled
/// true pixels, leakage over reconstructed pixels that are not on an unsampled true surface.
QualityMetrics compareToGroundTruth(const ReconstructionImages& reconstruction,
                                    const GroundTruthImages& truth, double spacing);

/// Peak signal-to-noise ratio of two RGBA8 images over their RGB channels, in dB (capped at
/// 100 dB for identical images).
double psnr(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b);

/// The mean of per-view metrics (optional ones averaged where present).
QualityMetrics average(const std::vector<QualityMetrics>& views);

/// One frame of a sequence: the picture (RGBA8, sRGB) and what it covers (1 per pixel where the
/// method shows the object, else 0).
struct SequenceFrame {
    std::vector<std::uint8_t> image;
    std::vector<std::uint8_t> mask;
};

/// DESIGN.md §7's measures of stability along a camera path, against the truth's sequence.
struct TemporalMetrics {
    /// E_t: mean over frames t >= 1, pixels and RGB of |(I_t - I_t-1) - (G_t - G_t-1)|, on the
    /// sRGB values scaled to 0..1: change the truth does not make.
    double temporalError = 0.0;
    /// The share of pixels whose covered state changes when the truth's does not, or the other
    /// way round, averaged over frames t >= 1.
    double maskFlicker = 0.0;
    double psnrDb = 0.0;  // mean over frames of each frame's PSNR against the truth's
};

/// Throws std::invalid_argument when the sequences differ in length or frame sizes.
TemporalMetrics compareSequences(const std::vector<SequenceFrame>& frames,
                                 const std::vector<SequenceFrame>& truth);

/// An RGBA8 sRGB image of (factor W) x (factor H) averaged over factor x factor blocks in linear
/// light and encoded again: a supersampled picture at W x H.
std::vector<std::uint8_t> downsampleSrgb(const std::vector<std::uint8_t>& image, int width,
                                         int height, int factor);

}  // namespace subscan
