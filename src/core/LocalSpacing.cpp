#include "core/LocalSpacing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "core/KdTree.h"
#include "core/Parallel.h"
#include "core/Spacing.h"

namespace subscan {

namespace {

/// Neighbours searched first; repeated points (overlapping scans) take some of them.
constexpr std::size_t kNeighbours = 12;
/// Neighbours searched when all of the first lie along the point's line: enough to reach the
/// next line where lines lie up to ~40 points' spacings apart (far ground of a station).
constexpr std::size_t kWideNeighbours = 96;
/// Which non-coincident neighbour's distance is the spacing: the 4th is past the pairs that
/// scanner noise and overlapping scans make, and still within the point's own surroundings.
constexpr std::size_t kSpacingNeighbour = 4;
/// A neighbour more than 45 degrees off the line's direction lies across it.
constexpr float kAcrossCosine = 0.70710678f;
/// Gaps across lines up to this many spacings are ordinary irregularity, not scan lines.
constexpr float kLineGapRatio = 2.0f;
/// Spacings within this factor of h are an even scan's sampling noise, not a change of density:
/// they count as h itself, so that an even scan renders as with h alone (measured on the
/// bunny's vertices, 1024², 8 views: without it, leakage 0.020 -> 0.025 and 0.7 dB less).
constexpr float kEvenSpread = 1.5f;
/// Half floats (the GPU's copy) end at 65504.
constexpr float kLargest = 6.0e4f;

using NearestIndices = std::array<std::uint32_t, kSpacingNeighbour>;

struct Neighbourhood {
    float spacingNeighbour = std::numeric_limits<float>::infinity();  // its distance
    glm::vec3 across{0.0f};
    NearestIndices nearest{};  // the first kSpacingNeighbour non-coincident ones (repeated
                               // when fewer)
    std::size_t distinct = 0;  // non-coincident neighbours looked at
};

/// The nearest neighbour of `point` across its line among `found` neighbours sorted by distance
/// (true when there is one), and the kSpacingNeighbour-th non-coincident distance (or the last
/// one found).
bool scanNeighbours(const std::vector<glm::vec3>& positions, const glm::vec3& point,
                    const std::uint32_t* indices, const float* squared, std::size_t found,
                    Neighbourhood& result) {
    std::size_t distinct = 0;
    glm::vec3 line{0.0f};
    bool acrossFound = false;
    for (std::size_t k = 0; k < found && !(acrossFound && distinct >= kSpacingNeighbour); ++k) {
        if (!(squared[k] > 0.0f)) {
            continue;
        }
        const glm::vec3 offset = positions[indices[k]] - point;
        const float distance = std::sqrt(squared[k]);
        ++distinct;
        result.distinct = distinct;
        if (distinct <= kSpacingNeighbour) {
            result.spacingNeighbour = distance;
            std::fill(result.nearest.begin() + static_cast<std::ptrdiff_t>(distinct - 1),
                      result.nearest.end(), indices[k]);
        }
        if (distinct == 1) {
            line = offset / distance;
        } else if (!acrossFound && std::abs(glm::dot(offset, line)) < kAcrossCosine * distance) {
            result.across = offset;
            acrossFound = true;
        }
    }
    return acrossFound;
}

Neighbourhood neighbourhoodOf(const KdTree& tree, const std::vector<glm::vec3>& positions,
                              const glm::vec3& point) {
    std::array<std::uint32_t, kWideNeighbours> indices{};
    std::array<float, kWideNeighbours> squared{};
    Neighbourhood result;
    const std::size_t found = tree.knnSearch(&point.x, kNeighbours, indices.data(), squared.data());
    const bool across =
        scanNeighbours(positions, point, indices.data(), squared.data(), found, result);
    // Wider when no neighbour lay across the line, or copies of points (overlapping scans)
    // left fewer than the spacing neighbour.
    if ((across && result.distinct >= kSpacingNeighbour) || found < kNeighbours) {
        return result;
    }
    const std::size_t wide =
        tree.knnSearch(&point.x, kWideNeighbours, indices.data(), squared.data());
    result = {};
    scanNeighbours(positions, point, indices.data(), squared.data(), wide, result);
    return result;
}

}  // namespace

float sparseSpacingRatio(const std::vector<glm::vec4>& spacing) {
    if (spacing.empty()) {
        return 1.0f;
    }
    std::vector<float> ratios(spacing.size());
    std::transform(spacing.begin(), spacing.end(), ratios.begin(), [](const glm::vec4& entry) {
        return std::max(entry.w, glm::length(glm::vec3(entry)));
    });
    const auto quantile = ratios.begin() + static_cast<std::ptrdiff_t>(
                                               0.999 * static_cast<double>(ratios.size() - 1));
    std::nth_element(ratios.begin(), quantile, ratios.end());
    return std::max(1.0f, *quantile);
}

void cutTheSparsest(std::vector<glm::vec4>& spacing) {
    if (spacing.empty()) {
        return;
    }
    const float largest = kSparsestReach * sparseSpacingRatio(spacing);
    for (glm::vec4& entry : spacing) {
        const glm::vec3 across(entry);
        const float length = glm::length(across);
        entry = glm::vec4(length > largest ? across * (largest / length) : across,
                          std::min(entry.w, largest));
    }
}

std::vector<glm::vec4> estimateLocalSpacing(const PointCloud& cloud, double h,
                                            const std::function<bool()>& cancelled) {
    const std::vector<glm::vec3>& positions = cloud.positions;
    std::vector<glm::vec4> spacing(positions.size(), glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    if (positions.size() < 2 || !(h > 0.0)) {
        return spacing;
    }
    const PositionsAdaptor adaptor{positions};
    const KdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    // Raw distances first (w: the spacing neighbour's, xyz: the across vector). In the tree's
    // own order, as estimateNormals queries: each thread's queries stay close together and
    // their nodes in the cache (a streamed view of 1 M Autzen points: 0.58-0.70 s of queries in
    // the file's order, 0.53-0.56 s in the tree's).
    std::vector<NearestIndices> nearest(positions.size());
    constexpr std::size_t kQueriesPerBlock = 4096;
    const bool stopped = inParallelBlocksUntil(
        positions.size(), kQueriesPerBlock, cancelled, [&](std::size_t query) {
            const std::size_t i = tree.vAcc[query];
            Neighbourhood found = neighbourhoodOf(tree, positions, positions[i]);
            if (!std::isfinite(found.spacingNeighbour)) {
                found.nearest.fill(static_cast<std::uint32_t>(i));
            }
            spacing[i] = glm::vec4(found.across, found.spacingNeighbour);
            nearest[i] = found.nearest;
        });
    if (stopped) {
        return spacing;
    }
    // The median over the point and its nearest neighbours: a point on a boundary (a
    // silhouette, a scan's edge) finds its 4th neighbour farther than inside, though the
    // points there lie no farther apart; most of its neighbours lie inside.
    std::vector<float> smoothed(positions.size());
    inParallel(positions.size(), [&](std::size_t i) {
        std::array<float, kSpacingNeighbour + 1> around{};
        around[0] = spacing[i].w;
        for (std::size_t k = 0; k < kSpacingNeighbour; ++k) {
            around[k + 1] = spacing[nearest[i][k]].w;
        }
        const auto middle = around.begin() + kSpacingNeighbour / 2;
        std::nth_element(around.begin(), middle, around.end());
        smoothed[i] = *middle;
    });
    for (std::size_t i = 0; i < spacing.size(); ++i) {
        spacing[i].w = smoothed[i];
    }
    std::vector<float> distances;
    distances.reserve(spacing.size());
    for (const glm::vec4& entry : spacing) {
        if (std::isfinite(entry.w)) {
            distances.push_back(entry.w);
        }
    }
    if (distances.empty()) {
        std::fill(spacing.begin(), spacing.end(), glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
        return spacing;
    }
    const auto middle = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
    std::nth_element(distances.begin(), middle, distances.end());
    const float median = *middle;
    const auto inverseH = static_cast<float>(1.0 / h);
    for (glm::vec4& entry : spacing) {
        // A point without neighbours (a cloud of repeated points) keeps the global h.
        float local = std::isfinite(entry.w) ? std::min(entry.w / median, kLargest) : 1.0f;
        if (local > 1.0f / kEvenSpread && local < kEvenSpread) {
            local = 1.0f;
        }
        const glm::vec3 across = glm::vec3(entry) * inverseH;
        const float acrossLength = glm::length(across);
        const bool acrossLines = acrossLength > kLineGapRatio * local && acrossLength < kLargest;
        entry = glm::vec4(acrossLines ? across : glm::vec3(0.0f), local);
    }
    cutTheSparsest(spacing);
    return spacing;
}

namespace {

/// `h` and, by the rule of kAlwaysLocalSpacingPoints, the local spacing; `sampledNearest`
/// gives sampled nearest distances when a large cloud needs them.
template <class SampledNearest>
PointSpacing withLocalSpacing(const PointCloud& cloud, double h, SampledNearest&& sampledNearest,
                              const std::function<bool()>& cancelled = {}) {
    PointSpacing spacing;
    spacing.global = h;
    if (!(h > 0.0) || !std::isfinite(h)) {
        return spacing;
    }
    if (cloud.size() <= kAlwaysLocalSpacingPoints || spacingVaries(sampledNearest())) {
        spacing.local = estimateLocalSpacing(cloud, h, cancelled);
    }
    return spacing;
}

}  // namespace

PointSpacing estimatePointSpacing(const PointCloud& cloud, std::optional<double> global) {
    if (!global) {
        return estimatePointSpacing(cloud, sampleSpacing(cloud));
    }
    // The sample estimateSpacing would take: the same decision as without a given h.
    return withLocalSpacing(cloud, *global, [&] { return sampledNearestDistances(cloud); });
}

PointSpacing estimatePointSpacing(const PointCloud& cloud, const SpacingSample& sample,
                                  const std::function<bool()>& cancelled) {
    return withLocalSpacing(
        cloud, sample.h, [&] { return sample.nearest; }, cancelled);
}

PointSpacing estimatePointSpacing(const PointCloud& cloud, std::span<const float> levelSpacing) {
    return withLevelSpacing(estimatePointSpacing(cloud), levelSpacing);
}

PointSpacing withLevelSpacing(PointSpacing spacing, std::span<const float> levelSpacing) {
    if (levelSpacing.empty()) {
        return spacing;
    }
    if (!spacing.local.empty() && levelSpacing.size() != spacing.local.size()) {
        throw std::invalid_argument("withLevelSpacing: one level spacing per point");
    }
    // The level most points lie on calibrates: a level's points lie its spacing over that
    // level's times as far apart as that level's do, whose estimate there is taken as their
    // lower quartile (its points beside a finer level estimate less, those where the scan is
    // sparser than the level more; without estimates, 1). Level spacing 0 (points at the
    // scan's own spacing) sets no minimum.
    std::map<float, std::size_t> pointsOn;
    for (const float level : levelSpacing) {
        if (level > 0.0f) {
            ++pointsOn[level];
        }
    }
    if (pointsOn.empty() ||
        (pointsOn.size() == 1 && pointsOn.begin()->second == levelSpacing.size())) {
        return spacing;  // no level, or one throughout: the estimate stands
    }
    const float dominant =
        std::max_element(pointsOn.begin(), pointsOn.end(), [](const auto& a, const auto& b) {
            return a.second < b.second;
        })->first;
    float calibration = 1.0f;
    if (!spacing.local.empty()) {
        std::vector<float> estimates;
        for (std::size_t i = 0; i < levelSpacing.size(); ++i) {
            if (levelSpacing[i] == dominant) {
                estimates.push_back(spacing.local[i].w);
            }
        }
        const auto quartile = estimates.begin() + static_cast<std::ptrdiff_t>(estimates.size() / 4);
        std::nth_element(estimates.begin(), quartile, estimates.end());
        calibration = *quartile;
    } else {
        // No scan lines, spacing h (estimateLocalSpacing's form: the across vector, then w).
        spacing.local.assign(levelSpacing.size(), glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    }
    for (std::size_t i = 0; i < levelSpacing.size(); ++i) {
        spacing.local[i].w = std::max(spacing.local[i].w, calibration * levelSpacing[i] / dominant);
    }
    return spacing;
}

bool spacingVaries(std::vector<float> sampledNearest) {
    std::erase_if(sampledNearest, [](float d) { return !std::isfinite(d); });
    if (sampledNearest.size() < 10) {
        return false;
    }
    const auto at = [&](double share) {
        const auto position =
            sampledNearest.begin() +
            static_cast<std::ptrdiff_t>(share * static_cast<double>(sampledNearest.size() - 1));
        std::nth_element(sampledNearest.begin(), position, sampledNearest.end());
        return *position;
    };
    const float low = at(0.1);
    const float high = at(0.9);
    return high > kVaryingSpacingRatio * low;
}

}  // namespace subscan
