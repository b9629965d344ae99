#include "app/viewer/CrossFade.h"

#include <algorithm>

#include "render/RenderPass.h"
#include "shared/bindings.h"

namespace subscan::viewer {

double crossFadeWeight(double elapsed) {
    const double t = std::clamp(elapsed / kCrossFadeSeconds, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

CrossFade::CrossFade(const ShaderSources& sources)
    : program_(Program::compute(sources, "viewer/CrossFade.comp")) {}

void CrossFade::start(const Texture& shown) {
    if (from_.width() != shown.width() || from_.height() != shown.height()) {
        from_ = Texture(TextureFormat::RGBA8, shown.width(), shown.height(), "cross-fade from");
        blended_ = Texture(TextureFormat::RGBA8, shown.width(), shown.height(), "cross-fade");
    }
    glCopyImageSubData(shown.id(), GL_TEXTURE_2D, 0, 0, 0, 0, from_.id(), GL_TEXTURE_2D, 0, 0, 0, 0,
                       shown.width(), shown.height(), 1);
    pending_ = true;
    started_ = -1.0;
}

bool CrossFade::active(const Texture& image, double now) const {
    // A picture of another size (the window changed) has nothing to fade from.
    return (pending_ || (started_ >= 0.0 && now - started_ < kCrossFadeSeconds)) &&
           image.width() == from_.width() && image.height() == from_.height();
}

const Texture& CrossFade::blend(const Texture& image, double now) {
    if (pending_) {
        pending_ = false;
        started_ = now;
    }
    program_.use();
    glUniform1f(SUBSCAN_UNIFORM_FADE, static_cast<float>(crossFadeWeight(now - started_)));
    from_.bindImage(SUBSCAN_IMAGE_IN0, GL_READ_ONLY);
    image.bindImage(SUBSCAN_IMAGE_IN1, GL_READ_ONLY);
    blended_.bindImage(SUBSCAN_IMAGE_OUT0, GL_WRITE_ONLY);
    Program::dispatch2D(image.width(), image.height(), SUBSCAN_IMAGE_GROUP_SIZE,
                        SUBSCAN_IMAGE_GROUP_SIZE);
    // The blit that presents it reads the texture as a framebuffer attachment; the next
    // start() may copy it, and tests read it back.
    glMemoryBarrier(kImageWritesBarrier | GL_FRAMEBUFFER_BARRIER_BIT);
    return blended_;
}

}  // namespace subscan::viewer
