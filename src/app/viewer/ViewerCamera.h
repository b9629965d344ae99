#pragma once

#include <optional>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "core/Camera.h"
#include "core/PointCloud.h"

namespace subscan::viewer {

/// The viewer's camera and how mouse and keys move it, as in CloudCompare or Potree: orbit
/// around a centre, pan, zoom towards the point under the cursor, re-centre on a picked point,
/// and a fly mode that turns around the eye. Pure maths, no window: every input is in pixels of
/// a viewport of the given size (origin top left, y down), as cursor positions are.
///
/// The state is an orbit: a centre, the eye's distance from it, and the direction towards the
/// eye as yaw and pitch around the scene's up axis (the parameters of orbitCamera), so the
/// up axis stays up whatever the user does.
class ViewerCamera {
  public:
    static constexpr double kFovyDegrees = 45.0;
    static constexpr double kDegreesPerPixel = 0.3;   // half a turn for a 600-pixel drag
    static constexpr double kZoomPerStep = 0.8;       // one wheel step closes 20% of the way
    static constexpr double kMaxPitchDegrees = 89.0;  // lookAt needs a horizon

    ViewerCamera() = default;
    /// The scene to frame; resets to the auto-framed view for a viewport of width x height,
    /// which fills the picture with `framed` (by default the bounds; see framingBounds()).
    ViewerCamera(const Bounds& bounds, UpAxis up, int width, int height,
                 std::optional<Bounds> framed = std::nullopt);

    /// The view orbitCamera gives with its default angles (what `R` goes back to).
    void reset(int width, int height);
    /// Keeps the viewing direction; centres the bounds and fits them into the viewport (`F`).
    void frameAll(int width, int height);

    /// Turns the eye around the centre for a drag of (dx, dy) pixels: right turns the scene
    /// right, down tilts its top towards the viewer.
    void orbit(double dxPixels, double dyPixels);
    /// Moves centre and eye together so that the scene at the centre's depth follows a drag of
    /// (dx, dy) pixels.
    void pan(double dxPixels, double dyPixels, int viewportHeight);
    /// Moves the eye `steps` wheel steps towards `target` (positive: closer), the centre
    /// with it, keeping the direction: `target` stays under the same pixel.
    void zoomTowards(double steps, const glm::dvec3& target);
    /// Fly mode: turns the view around the eye for a drag of (dx, dy) pixels.
    void look(double dxPixels, double dyPixels);
    /// Fly mode: moves eye and centre together by the given scene units along the view's right,
    /// up and backward axes.
    void move(const glm::dvec3& rightUpBack);
    /// Orbits around `point` from now on; the eye stays where it is and turns towards it.
    void setCentre(const glm::dvec3& point);
    /// Puts the eye at `eye`, orbiting `target` (the sensor view, `V`); the pitch stays within
    /// kMaxPitchDegrees of the horizon, as every view of this camera does.
    void lookFrom(const glm::dvec3& eye, const glm::dvec3& target);

    /// A directional light's direction (towards the light, scene coordinates) after a drag of
    /// (dx, dy) pixels with `L` held. The light turns around the scene in the frame of this
    /// view: its azimuth around the view's up axis (a drag to the right moves a light in front
    /// of the scene to the right) and its elevation towards that axis (a drag upwards raises
    /// it), kDegreesPerPixel as for orbit, the elevation stopping kMaxPitchDegrees short of the
    /// view's up and down where the azimuth would be lost. The camera does not move; the result
    /// is a unit vector (a zero direction starts from the eye's side).
    glm::dvec3 dragLight(const glm::dvec3& towardsLight, double dxPixels, double dyPixels) const;
    /// The light `L` adds when there is none: from the upper left of this view, on the eye's
    /// side of the scene (45 degrees to the left, 35 up), a unit vector.
    glm::dvec3 defaultLightDirection() const;

    /// The camera for a viewport of width x height pixels; near and far hug the scene.
    Camera camera(int width, int height) const;

    glm::dvec3 eye() const;
    const glm::dvec3& centre() const { return centre_; }
    double distance() const { return distance_; }
    double yawDegrees() const { return yawDegrees_; }
    double pitchDegrees() const { return pitchDegrees_; }
    /// The radius of the scene's bounding sphere (the scale for speeds and limits).
    double sceneRadius() const { return sceneRadius_; }
    /// Unit vectors of the view in scene coordinates.
    glm::dvec3 forward() const;
    glm::dvec3 right() const;
    glm::dvec3 up() const;

    /// Where the cursor at `pixel` of a width x height viewport points, at the centre's depth
    /// (the zoom target when nothing lies under the cursor).
    glm::dvec3 pointAtCentreDepth(const glm::dvec2& pixel, int width, int height) const;
    /// The scene point at linear view depth `depth` under `pixel`, for a camera `camera` (the
    /// one the depth was rendered with).
    static glm::dvec3 unproject(const Camera& camera, const glm::dvec2& pixel, double depth);

  private:
    /// From the centre towards the eye.
    glm::dvec3 towardsEye() const;
    void clampDistance();

    Bounds bounds_;
    std::optional<Bounds> framed_;
    UpAxis up_ = UpAxis::Y;
    double sceneRadius_ = 1.0;
    glm::dvec3 centre_{0.0};
    double distance_ = 1.0;
    double yawDegrees_ = 0.0;
    double pitchDegrees_ = 0.0;
};

}  // namespace subscan::viewer
