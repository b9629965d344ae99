#pragma once

#include <optional>

#include "scan/Scene.h"

namespace subscan {

/// A scene whose surface is the zero set of a signed distance bound f (negative inside) that is
/// 1-Lipschitz: |f(p)| never exceeds the distance from p to the surface, and is 0 on it.
///
/// Rays are sphere traced: steps of |f| cannot pass the surface, and a minimum step of 1e-6 of
/// the scene size ends the slow approach at grazing angles by stepping across it. The crossing
/// is then bracketed by a sign change of f and refined (Illinois regula falsi) until the bracket
/// is 1e-11 of the scene size wide, so hits lie on the surface to far below any noise we model.
/// Parts thinner than the minimum step can be missed by a ray grazing them, never hit falsely.
class SignedDistanceScene : public Scene {
  public:
    /// `bounds` must contain the whole surface.
    explicit SignedDistanceScene(const Bounds& bounds);

    std::optional<SurfaceHit> intersect(const Ray& ray, double maxDistance) const final;
    Bounds bounds() const final { return bounds_; }
    double surfaceDistance(const glm::dvec3& p) const final;

    virtual double signedDistance(const glm::dvec3& p) const = 0;

  protected:
    /// Unit outward normal at a surface point. The default is the normalised central-difference
    /// gradient of f; override where an analytic normal is easy.
    virtual glm::dvec3 outwardNormal(const glm::dvec3& p) const;
    /// Linear RGB albedo at a surface point.
    virtual glm::vec3 albedo(const glm::dvec3& p) const = 0;

    /// Length of the bounds' diagonal: the scale of every tolerance.
    double size() const { return size_; }

  private:
    double refineCrossing(const Ray& ray, double before, double valueBefore, double after,
                          double valueAfter) const;

    Bounds bounds_;
    double size_;
};

}  // namespace subscan
