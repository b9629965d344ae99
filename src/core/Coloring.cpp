#include "core/Coloring.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/Error.h"

namespace subscan {

namespace {

constexpr std::pair<Coloring, std::string_view> kColorings[] = {
    {Coloring::Auto, "auto"},           {Coloring::Rgb, "rgb"},
    {Coloring::Intensity, "intensity"}, {Coloring::Height, "height"},
    {Coloring::Uniform, "uniform"},     {Coloring::Classification, "classification"},
};

/// classificationColor's table, indexed by class code 0-18.
constexpr std::array<Rgba8, 19> kClassColors{{
    {160, 160, 160, 255},  // 0 created, never classified
    {215, 215, 215, 255},  // 1 unclassified
    {150, 95, 50, 255},    // 2 ground
    {150, 225, 100, 255},  // 3 low vegetation
    {60, 170, 60, 255},    // 4 medium vegetation
    {20, 100, 35, 255},    // 5 high vegetation
    {235, 110, 35, 255},   // 6 building
    {230, 0, 230, 255},    // 7 low point (noise)
    {255, 225, 0, 255},    // 8 model key-point (LAS 1.0-1.3), reserved (1.4)
    {30, 100, 230, 255},   // 9 water
    {120, 70, 170, 255},   // 10 rail
    {70, 70, 85, 255},     // 11 road surface
    {255, 255, 160, 255},  // 12 overlap (LAS 1.0-1.3), reserved (1.4)
    {255, 170, 200, 255},  // 13 wire guard (shield)
    {0, 210, 210, 255},    // 14 wire conductor (phase)
    {160, 30, 30, 255},    // 15 transmission tower
    {0, 110, 130, 255},    // 16 wire-structure connector (insulator)
    {205, 175, 130, 255},  // 17 bridge deck
    {255, 40, 40, 255},    // 18 high noise
}};
constexpr Rgba8 kOtherClassColor{128, 128, 128, 255};

constexpr Rgba8 kUniform{200, 200, 200, 255};

/// The 1st and 99th percentile of `value(i)` over a sample of at most ~100,000 points.
template <class Value>
std::pair<float, float> percentiles(std::size_t count, Value value) {
    std::vector<float> sample;
    const std::size_t step = std::max<std::size_t>(1, count / 100000);
    for (std::size_t i = 0; i < count; i += step) {
        sample.push_back(value(i));
    }
    std::sort(sample.begin(), sample.end());
    return {sample[sample.size() / 100], sample[sample.size() - 1 - sample.size() / 100]};
}

/// Viridis at t in 0..1, from five of its stops (sRGB), blended linearly between them.
Rgba8 viridis(float t) {
    constexpr std::array<std::array<float, 3>, 5> kStops{
        {{68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}}};
    const float x = std::clamp(t, 0.0f, 1.0f) * static_cast<float>(kStops.size() - 1);
    const auto below = std::min(static_cast<std::size_t>(x), kStops.size() - 2);
    const float f = x - static_cast<float>(below);
    std::array<std::uint8_t, 3> rgb{};
    for (std::size_t c = 0; c < 3; ++c) {
        rgb[c] = static_cast<std::uint8_t>(
            std::lround(kStops[below][c] + f * (kStops[below + 1][c] - kStops[below][c])));
    }
    return {rgb[0], rgb[1], rgb[2], 255};
}

}  // namespace

std::string toString(Coloring coloring) {
    for (const auto& [value, name] : kColorings) {
        if (value == coloring) {
            return std::string(name);
        }
    }
    return "auto";
}

Coloring parseColoring(std::string_view text) {
    for (const auto& [value, name] : kColorings) {
        if (name == text) {
            return value;
        }
    }
    throw Error(
        fmt::format("there is no colouring '{}' ({})", text, fmt::join(coloringNames(), ", ")));
}

std::vector<std::string> coloringNames() {
    std::vector<std::string> names;
    for (const auto& [value, name] : kColorings) {
        names.emplace_back(name);
    }
    return names;
}

Rgba8 classificationColor(std::uint8_t code) {
    return code < kClassColors.size() ? kClassColors[code] : kOtherClassColor;
}

std::vector<std::uint8_t> intensityGreys(const PointCloud& cloud) {
    std::vector<std::uint8_t> greys(cloud.size());
    if (cloud.size() == 0) {
        return greys;
    }
    const auto [low, high] =
        percentiles(cloud.size(), [&](std::size_t i) { return cloud.intensities[i]; });
    const float range = high > low ? high - low : 1.0f;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const float t = std::clamp((cloud.intensities[i] - low) / range, 0.0f, 1.0f);
        greys[i] = static_cast<std::uint8_t>(std::lround(40.0f + 215.0f * t));
    }
    return greys;
}

std::vector<Rgba8> pointColors(const PointCloud& cloud, Coloring coloring, UpAxis up) {
    if (coloring == Coloring::Auto) {
        coloring = cloud.hasColors() ? Coloring::Rgb
                   : up == UpAxis::Z ? Coloring::Height
                                     : Coloring::Uniform;
    }
    switch (coloring) {
        case Coloring::Rgb:
            if (!cloud.hasColors()) {
                throw Error("the scan has no colours to show (try --color height or intensity)");
            }
            return cloud.colors;
        case Coloring::Intensity: {
            if (!cloud.hasIntensities()) {
                throw Error("the scan has no intensities to show (try --color height or rgb)");
            }
            std::vector<Rgba8> colors;
            colors.reserve(cloud.size());
            for (const std::uint8_t grey : intensityGreys(cloud)) {
                colors.push_back({grey, grey, grey, 255});
            }
            return colors;
        }
        case Coloring::Height: {
            const int axis = up == UpAxis::Z ? 2 : 1;
            const float sign = up == UpAxis::NegativeY ? -1.0f : 1.0f;
            std::vector<Rgba8> colors;
            colors.reserve(cloud.size());
            if (cloud.size() == 0) {
                return colors;
            }
            const auto [low, high] = percentiles(
                cloud.size(), [&](std::size_t i) { return sign * cloud.positions[i][axis]; });
            const float range = high > low ? high - low : 1.0f;
            for (const glm::vec3& position : cloud.positions) {
                colors.push_back(viridis((sign * position[axis] - low) / range));
            }
            return colors;
        }
        case Coloring::Classification: {
            if (!cloud.hasClassifications()) {
                throw Error(
                    "the scan has no classification to show (only LAS, LAZ and COPC files carry "
                    "one; try --color height or rgb)");
            }
            std::vector<Rgba8> colors;
            colors.reserve(cloud.size());
            for (const std::uint8_t code : cloud.classifications) {
                colors.push_back(classificationColor(code));
            }
            return colors;
        }
        case Coloring::Uniform:
        case Coloring::Auto:
            break;
    }
    return std::vector<Rgba8>(cloud.size(), kUniform);
}

}  // namespace subscan
