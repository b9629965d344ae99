#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <glm/vec3.hpp>

#include "core/PointCloud.h"

namespace subscan {

/// The sRGB transfer function (IEC 61966-2-1), for one channel in 0..1; the CPU twins of
/// srgbToLinear/linearToSrgb in shaders/shared/common.glsl.
inline float srgbToLinear(float encoded) {
    return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

inline float linearToSrgb(float linear) {
    return linear <= 0.0031308f ? linear * 12.92f : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

/// An 8-bit sRGB colour as linear RGB.
inline glm::vec3 linearColor(const Rgba8& color) {
    return {srgbToLinear(color.r / 255.0f), srgbToLinear(color.g / 255.0f),
            srgbToLinear(color.b / 255.0f)};
}

/// One linear channel (clamped to 0..1) encoded as 8-bit sRGB, rounded to nearest.
inline std::uint8_t srgb8Channel(float linear) {
    return static_cast<std::uint8_t>(
        std::lround(linearToSrgb(std::clamp(linear, 0.0f, 1.0f)) * 255.0f));
}

/// Linear RGB (clamped to 0..1) encoded as opaque 8-bit sRGB, rounded to nearest.
inline Rgba8 srgb8Color(const glm::vec3& linear) {
    return {srgb8Channel(linear.r), srgb8Channel(linear.g), srgb8Channel(linear.b), 255};
}

}  // namespace subscan
