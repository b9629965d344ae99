#include "render/Reconstruction.h"

#include "render/FillRemovalPass.h"
#include "render/HiddenPointRemovalPass.h"
#include "render/MinDepthPyramidPass.h"
#include "render/NormalsPass.h"
#include "render/PullPushPass.h"
#include "render/RasterizePointsPass.h"

namespace subscan {

Reconstruction::Reconstruction(const ShaderSources& sources, const GlCapabilities& capabilities)
    : sources_(sources), capabilities_(capabilities) {}

Reconstruction::~Reconstruction() = default;

void Reconstruction::appendRasterization(std::vector<RenderPass*>& passes) {
    passes.push_back(&lazyPass(rasterize_, sources_, capabilities_));
}

void Reconstruction::appendSurface(std::vector<RenderPass*>& passes, LevelZero levelZero) {
    passes.push_back(&lazyPass(minDepthPyramid_, sources_));
    passes.push_back(&lazyPass(hiddenPointRemoval_, sources_));
    PullPushPass& pullPush = lazyPass(pullPush_, sources_);
    FillRemovalPass& fillRemoval = lazyPass(fillRemoval_, sources_);
    NormalsPass& normals = lazyPass(normals_, sources_);
    pullPush.setLevelZero(levelZero);
    fillRemoval.setLevelZero(levelZero);
    normals.setLevelZero(levelZero);
    passes.insert(passes.end(), {&pullPush, &fillRemoval, &normals});
}

void Reconstruction::appendAll(std::vector<RenderPass*>& passes) {
    appendRasterization(passes);
    appendSurface(passes, LevelZero::PerPass);
}

}  // namespace subscan
