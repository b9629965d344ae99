#include "app/viewer/ScanLoadJob.h"

#include <new>
#include <utility>

#include "core/Error.h"
#include "core/Spacing.h"
#include "lod/NodeSelection.h"
#include "render/Renderer.h"

namespace subscan::viewer {

namespace {

/// Thrown from the progress callback to abandon a load nobody waits for any more.
struct LoadCancelled {};

}  // namespace

ScanLoadJob::ScanLoadJob(std::string source, const StreamingSettings& streaming)
    : source_(std::move(source)),
      streaming_(streaming),
      job_(source_, [this](const std::function<bool()>& cancelled) { return load(cancelled); }) {}

PreparedScan ScanLoadJob::load(const std::function<bool()>& cancelled) {
    const auto reportProgress = [this, &cancelled](double fraction) {
        if (cancelled()) {
            throw LoadCancelled{};
        }
        progress_.store(fraction, std::memory_order_relaxed);
    };
    try {
        PreparedScan prepared;
        prepared.source = source_;
        if (std::shared_ptr<const lod::NodeSource> opened =
                lod::openStreamed(source_, streaming_.lod)) {
            prepared.streamed = std::make_shared<lod::CachedNodeSource>(
                std::move(opened), streaming_.nodeCacheMegabytes << 20);
            prepared.scan = lod::loadStreamedOverview(*prepared.streamed, &prepared.nodes);
        } else {
            prepared.scan = loadScan(source_, reportProgress);
        }
        // Both show at once: a survey's overview only until the view's own nodes come (the
        // local spacing's neighbour search took 131-136 ms of Autzen 60 x 60's first picture,
        // 0.8-1.0 s); a whole scan until its spacing and normals are complete (the viewer's
        // completeSpacing).
        prepareProvisionally(prepared);
        return prepared;
    } catch (const LoadCancelled&) {
        throw Error(source_ + ": loading was cancelled");
    } catch (const std::bad_alloc&) {
        throw Error(source_ + ": out of memory (the scan is too large for this machine)");
    }
}

std::optional<CompletedSpacing> completeSpacing(const PointCloud& cloud,
                                                const SpacingSample& sample,
                                                const std::function<bool()>& cancelled) {
    try {
        CompletedSpacing completed;
        completed.spacing = estimatePointSpacing(cloud, sample, cancelled);
        if (cancelled()) {
            return std::nullopt;
        }
        const std::vector<glm::vec3> normals = normalsFor(cloud, NormalSource::Auto, cancelled);
        if (cancelled()) {
            return std::nullopt;
        }
        completed.packed = packPointAttributes(completed.spacing.local, normals);
        return completed;
    } catch (const std::bad_alloc&) {
        throw Error("out of memory for the scan's local spacing and normals");
    }
}

void prepareProvisionally(PreparedScan& prepared) {
    prepared.sample = sampleSpacing(prepared.scan.cloud);
    prepared.spacing =
        withLevelSpacing(PointSpacing{prepared.sample.h, {}}, prepared.scan.levelSpacing);
    prepared.packed = packPointAttributes(prepared.spacing.local, {});
    prepared.provisional = true;
}

bool prepareForRenderer(PreparedScan& prepared, const std::function<bool()>& cancelled) {
    prepared.spacing = estimatePointSpacing(prepared.scan.cloud, prepared.scan.levelSpacing);
    if (cancelled()) {
        return false;
    }
    prepared.packed = packPointAttributes(prepared.spacing.local, {});
    return true;
}

}  // namespace subscan::viewer
