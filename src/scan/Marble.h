#pragma once

#include <glm/vec3.hpp>

#include "core/PointCloud.h"

namespace subscan {

/// Procedural marble: white stone with grey-green veins, from 3-D gradient noise and turbulence
/// (Perlin 1985). A pure function of position, so every point of a surface gets the same colour
/// in every scan and in the ground-truth rendering.
class MarbleAlbedo {
  public:
    struct Palette {
        glm::vec3 stone;  // linear RGB of the background stone
        glm::vec3 vein;   // linear RGB at the centre of a vein
    };
    /// White Carrara-like stone (its mean albedo is near Jensen's measured marble, 0.83 0.79 0.75)
    /// with grey-green veins.
    static constexpr Palette kWhite{{0.83f, 0.80f, 0.75f}, {0.26f, 0.32f, 0.28f}};
    /// Dark green stone with pale veins, for plinths.
    static constexpr Palette kVerde{{0.10f, 0.16f, 0.12f}, {0.62f, 0.66f, 0.60f}};

    /// `featureSize`: the distance between main veins, in scene units.
    explicit MarbleAlbedo(double featureSize, Palette palette = kWhite);

    /// Veins about a quarter of the object's size apart, which reads as marble at any scale.
    static MarbleAlbedo forBounds(const Bounds& bounds, Palette palette = kWhite);

    /// Linear RGB albedo at p, 0..1.
    glm::vec3 operator()(const glm::dvec3& p) const;

  private:
    double inverseFeatureSize_;
    Palette palette_;
};

/// Perlin's improved gradient noise at p: smooth, about -1..1, zero at integer lattice points.
/// Deterministic everywhere (a hash of the lattice cell, no tables or random state).
double gradientNoise(const glm::dvec3& p);

}  // namespace subscan
