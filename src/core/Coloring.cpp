#include "core/Coloring.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "core/Error.h"

namespace subscan {

namespace {

constexpr std::pair<Coloring, std::string_view> kColorings[] = {
    {Coloring::Auto, "auto"},           {Coloring::Rgb, "rgb"},
    {Coloring::Intensity, "intensity"}, {Coloring::Height, "height"},
    {Coloring::Uniform, "uniform"},
};

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
        fmt::format("there is no colouring '{}' (auto, rgb, intensity, height, uniform)", text));
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
            std::vector<Rgba8> colors;
            colors.reserve(cloud.size());
            if (cloud.size() == 0) {
                return colors;
            }
            const auto [low, high] =
                percentiles(cloud.size(), [&](std::size_t i) { return cloud.positions[i][axis]; });
            const float range = high > low ? high - low : 1.0f;
            for (const glm::vec3& position : cloud.positions) {
                colors.push_back(viridis((position[axis] - low) / range));
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
