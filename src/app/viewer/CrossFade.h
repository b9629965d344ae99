#pragma once

#include "gpu/GlObjects.h"
#include "gpu/ShaderSources.h"

namespace subscan::viewer {

/// How long the viewer fades from one set of a streamed view's nodes to the next: long enough
/// that the change reads as a refinement, not a jump; short enough to be over before the eye
/// looks for it.
inline constexpr double kCrossFadeSeconds = 0.3;

/// The new picture's weight `elapsed` seconds into a fade: 0 at its start, 1 from its end on,
/// easing in and out (smoothstep) so that neither end shows a kink in brightness.
double crossFadeWeight(double elapsed);

/// A cross-fade from the picture on screen to the next one (CrossFade.comp), so that a
/// streamed view's nodes arriving or leaving do not pop: the old picture is kept when the
/// nodes change, and each frame until the fade ends shows the new one mixed over it. The fade's
/// clock starts with the first frame that blends: the new points' first frame may take longer
/// than the fade itself on llvmpipe (0.25 s at 1280x720), which left one frame of it.
class CrossFade {
  public:
    explicit CrossFade(const ShaderSources& sources);

    /// Keeps a copy of `shown` (an RGBA8 picture) to fade from.
    void start(const Texture& shown);
    /// Whether a fade is started or under way at `now` for pictures the size of `image`.
    bool active(const Texture& image, double now) const;
    /// `image` mixed over the kept picture by the fade's weight at `now` (0 at the first
    /// blend after start()); what to present. Only while active().
    const Texture& blend(const Texture& image, double now);
    void stop() {
        pending_ = false;
        started_ = -1.0;
    }
    /// The last blend(): what is on screen while a fade is under way.
    const Texture& blended() const { return blended_; }

  private:
    Program program_;
    Texture from_;
    Texture blended_;
    bool pending_ = false;   // started, not yet blended
    double started_ = -1.0;  // the first blend's time; < 0: no fade
};

}  // namespace subscan::viewer
