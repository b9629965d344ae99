#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/viewer/BackgroundJob.h"
#include "core/Coloring.h"
#include "core/LocalSpacing.h"
#include "core/Spacing.h"
#include "io/ScanLoader.h"
#include "lod/NodeCache.h"
#include "render/GpuPointCloud.h"
#include "render/RenderSettings.h"

namespace subscan::viewer {

/// A scan as the viewer needs it: the cloud for the GPU upload, its spacing (h and the local
/// spacing), all made off the render thread; a scan loaded whole gets its local spacing and
/// normals later (completeSpacing), a streamed one estimates no normals (streamedNormals).
struct PreparedScan {
    std::string source;
    LoadedScan scan;
    PointSpacing spacing;  // estimatePointSpacing's result (h = 0: the renderer picks one)
    /// A scan loaded whole, provisional: `spacing` is h alone, from this sample, which
    /// completeSpacing goes on from.
    SpacingSample sample;
    PackedPointAttributes packed;  // the local spacing as the GPU reads it
    /// The points' colours as the viewer shows them under `coloredBy` (pointColors), where the
    /// job knew how it colours them; else empty, and the viewer colours them itself.
    std::vector<Rgba8> shownColors;
    std::optional<std::pair<Coloring, UpAxis>> coloredBy;
    /// `spacing` is h alone (and a streamed scan's levels' spacing), without the local spacing's
    /// neighbour search: a scan loaded whole (h from `sample`) gets the rest after its first
    /// picture (completeSpacing), a streamed one with the nodes of its view, which it shows
    /// only until then (the overview, a view's partial sets).
    bool provisional = false;
    /// A COPC file or EPT dataset streamed by its levels of detail: the scan holds `nodes` of
    /// it (the overview when first opened, then the nodes a view shows). Null: loaded whole.
    std::shared_ptr<const lod::CachedNodeSource> streamed;
    std::vector<std::size_t> nodes;
};

/// What a scan loaded whole lacks after its provisional first picture: its spacing (h and the
/// local spacing) and normals, estimated as prepareForRenderer does, packed for the GPU.
struct CompletedSpacing {
    PointSpacing spacing;
    PackedPointAttributes packed;
};
/// Estimates them for `cloud` from its spacing `sample` (read, not changed, while the render
/// thread draws it: h stays the sample's); nullopt where `cancelled` turned true meanwhile.
/// Throws subscan::Error where memory runs out.
std::optional<CompletedSpacing> completeSpacing(const PointCloud& cloud,
                                                const SpacingSample& sample,
                                                const std::function<bool()>& cancelled);

/// Gives `prepared` (a streamed scan's nodes) h and its levels' spacing only, packed for the
/// GPU: PreparedScan::provisional.
void prepareProvisionally(PreparedScan& prepared);

/// Estimates the spacing of `prepared` (a streamed view's nodes: h, the local spacing and the
/// levels' spacing) and packs it for the GPU, here off the render thread; no normals, as
/// streamedNormals(auto) says. Returns false where `cancelled` turned true meanwhile.
bool prepareForRenderer(PreparedScan& prepared, const std::function<bool()>& cancelled);

/// Loads a scan on a thread of its own so that the window keeps drawing (with a progress bar)
/// while a big file is decoded; a COPC file or EPT dataset only its overview (topLevels), which
/// StreamedViewJob refines, through a lod::CachedNodeSource that every later view shares. Both
/// come provisional: a scan loaded whole (h from a sample, no local spacing or normals) shows
/// while completeSpacing estimates the rest, the overview until the view's nodes come.
/// Destroying an unfinished job cancels it at the reader's next progress report and waits for the
/// thread.
class ScanLoadJob {
  public:
    /// `streaming`: whether a COPC file or EPT dataset is streamed, and its nodes' cache.
    ScanLoadJob(std::string source, const StreamingSettings& streaming);

    const std::string& source() const { return source_; }
    /// 0..1 while the file is decoded; readers of small files and synthetic scenes report
    /// nothing until they are done.
    double progress() const { return progress_.load(std::memory_order_relaxed); }
    bool finished() const { return job_.finished(); }
    /// The result once finished(); rethrows the load's subscan::Error. Call at most once.
    PreparedScan take() { return job_.take(); }

  private:
    PreparedScan load(const std::function<bool()>& cancelled);

    std::string source_;
    StreamingSettings streaming_;
    std::atomic<double> progress_{0.0};
    BackgroundJob<PreparedScan> job_;  // last: starts once everything it touches exists
};

}  // namespace subscan::viewer
