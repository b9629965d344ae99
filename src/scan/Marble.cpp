#include "scan/Marble.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace subscan {

namespace {

/// A well-mixed 32-bit hash of a lattice cell (multiplicative mix, then MurmurHash3's fmix32).
std::uint32_t hashCell(std::int64_t x, std::int64_t y, std::int64_t z) {
    std::uint32_t h = static_cast<std::uint32_t>(x) * 0x8da6b343u ^
                      static_cast<std::uint32_t>(y) * 0xd8163841u ^
                      static_cast<std::uint32_t>(z) * 0xcb1ab31fu;
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

/// Dot product of (x, y, z) with one of Perlin's 12 cube-edge gradients chosen by the hash.
double gradientDot(std::uint32_t hash, double x, double y, double z) {
    const std::uint32_t h = hash & 15u;
    const double u = h < 8 ? x : y;
    const double v = h < 4 ? y : (h == 12 || h == 14 ? x : z);
    return ((h & 1u) == 0 ? u : -u) + ((h & 2u) == 0 ? v : -v);
}

double fade(double t) {
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

double lerp(double a, double b, double t) {
    return a + t * (b - a);
}

/// Sum of |noise| over octaves, each twice the frequency and half the weight: the folds of
/// |noise| give the sharp, branching look of marble veins.
double turbulence(const glm::dvec3& p, int octaves) {
    double sum = 0.0;
    double scale = 1.0;
    for (int octave = 0; octave < octaves; ++octave) {
        sum += std::abs(gradientNoise(p * scale)) / scale;
        scale *= 2.0;
    }
    return sum;
}

/// 1 at the centre of a vein (where `phase` is an integer), falling to 0 between veins;
/// `sharpness` narrows it.
double vein(double phase, double sharpness) {
    return std::pow(1.0 - std::abs(std::sin(std::numbers::pi * phase)), sharpness);
}

}  // namespace

double gradientNoise(const glm::dvec3& p) {
    const glm::dvec3 cell = glm::floor(p);
    const auto x = static_cast<std::int64_t>(cell.x);
    const auto y = static_cast<std::int64_t>(cell.y);
    const auto z = static_cast<std::int64_t>(cell.z);
    const glm::dvec3 f = p - cell;
    const double u = fade(f.x), v = fade(f.y), w = fade(f.z);
    auto corner = [&](int dx, int dy, int dz) {
        return gradientDot(hashCell(x + dx, y + dy, z + dz), f.x - dx, f.y - dy, f.z - dz);
    };
    return lerp(lerp(lerp(corner(0, 0, 0), corner(1, 0, 0), u),
                     lerp(corner(0, 1, 0), corner(1, 1, 0), u), v),
                lerp(lerp(corner(0, 0, 1), corner(1, 0, 1), u),
                     lerp(corner(0, 1, 1), corner(1, 1, 1), u), v),
                w);
}

MarbleAlbedo::MarbleAlbedo(double featureSize, Palette palette)
    : inverseFeatureSize_(1.0 / featureSize), palette_(palette) {}

MarbleAlbedo MarbleAlbedo::forBounds(const Bounds& bounds, Palette palette) {
    const double size = bounds.empty() ? 1.0 : glm::length(bounds.extent());
    return MarbleAlbedo(size > 0.0 ? 0.25 * size : 1.0, palette);
}

glm::vec3 MarbleAlbedo::operator()(const glm::dvec3& p) const {
    const glm::dvec3 q = p * inverseFeatureSize_;
    // Main veins: sheets across a tilted direction, bent by turbulence. The constant offsets
    // decorrelate the noise fields from one another.
    const double mainPhase = glm::dot(q, glm::dvec3(0.55, 0.80, 0.25)) + 1.1 * turbulence(q, 5);
    const double main = 0.85 * vein(mainPhase, 7.0) + 0.12 * vein(mainPhase, 2.0);
    // Finer, fainter veins crossing the main ones.
    const glm::dvec3 q2 = q * 2.7 + glm::dvec3(5.2, 1.3, 7.7);
    const double finePhase =
        glm::dot(q2, glm::dvec3(-0.3, 0.5, 0.8)) + 1.0 * turbulence(q2 * 0.7, 4);
    const double fine = 0.3 * vein(finePhase, 16.0);
    // Broad cloudiness of the stone itself, a few percent.
    const double cloud = gradientNoise(q * 0.8 + glm::dvec3(17.1, 3.3, 9.4));
    const auto stone = palette_.stone * static_cast<float>(1.0 + 0.05 * cloud);
    const auto amount = static_cast<float>(std::clamp(main + fine, 0.0, 1.0));
    return glm::clamp(glm::mix(stone, palette_.vein, amount), 0.0f, 1.0f);
}

}  // namespace subscan
