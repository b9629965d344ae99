#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "app/viewer/BackgroundJob.h"
#include "app/viewer/ScanLoadJob.h"
#include "core/Camera.h"
#include "lod/NodeCache.h"

namespace subscan::viewer {

/// How many more points each partial set of a view holds, shown while the rest of its nodes
/// load: a quarter of the budget, where the budget is at least four times
/// kAlwaysLocalSpacingPoints (a GPU's default, 10 M points: on llvmpipe's 2 cores Autzen's
/// first quarter showed after 2.4 s and the whole after 23 s, against 16.5 s for the whole
/// alone, the partial sets' frames taking their share of the cores); 0 (none) below, as on
/// llvmpipe's default of 1 M, whose whole view comes within about 1.5 s.
std::uint64_t partialViewPoints(std::uint64_t pointBudget);

/// Where a view's `nodes` (in the order lod::selectNodes chose them, the largest on screen first)
/// are cut into partial sets of about `partialPoints` more points each: the lengths of the
/// prefixes shown before the whole, ascending, the whole itself not among them. None for
/// `partialPoints` 0.
std::vector<std::size_t> partialViewEnds(std::span<const lod::StreamedNode> all,
                                         std::span<const std::size_t> nodes,
                                         std::uint64_t partialPoints);

/// The nodes of a streamed scan that a camera shows within a point budget (lod::selectNodes),
/// loaded and prepared for the renderer on a thread of its own: the window keeps drawing the
/// nodes it has meanwhile, and nothing in a frame waits for the disk. With `partialPoints`
/// (partialViewPoints) the first nodes are offered on the way (takePartial). Destroying an
/// unfinished job cancels it and waits for the thread.
class StreamedViewJob {
  public:
    /// `shown`: the nodes on screen now; a view that selects the same ones loads nothing.
    /// `coloredBy`: how the viewer colours the points (PreparedScan::shownColors).
    StreamedViewJob(std::shared_ptr<const lod::CachedNodeSource> source, std::string sourceName,
                    const Camera& camera, std::uint64_t pointBudget, std::vector<std::size_t> shown,
                    std::pair<Coloring, UpAxis> coloredBy, std::uint64_t partialPoints = 0);

    bool finished() const { return job_.finished(); }
    /// Once finished(): the view's nodes prepared, or nullopt where they are the ones shown.
    /// Rethrows a subscan::Error of the load. Call at most once.
    std::optional<PreparedScan> take() { return job_.take(); }
    /// The latest partial set of the view's nodes prepared since the last call, if any.
    std::optional<PreparedScan> takePartial();
    /// Partial sets prepared so far (taken or not).
    std::size_t partialsPrepared() const;

  private:
    std::optional<PreparedScan> load(const std::function<bool()>& cancelled);
    /// `nodes` loaded and prepared; nullopt where `cancelled` turned true meanwhile. A
    /// `provisional` set (a partial one) takes h and the levels' spacing without the local
    /// spacing's neighbour search, which for every partial set again made the whole view come
    /// 2.2 times later (Autzen at 10 M points: 37 s instead of 16.5 s).
    std::optional<PreparedScan> prepare(std::vector<std::size_t> nodes,
                                        const std::function<bool()>& cancelled,
                                        bool provisional) const;

    std::shared_ptr<const lod::CachedNodeSource> source_;
    std::string sourceName_;
    Camera camera_;
    std::uint64_t pointBudget_;
    std::vector<std::size_t> shown_;
    std::pair<Coloring, UpAxis> coloredBy_;
    std::uint64_t partialPoints_;
    mutable std::mutex partialMutex_;
    std::optional<PreparedScan> partial_;
    std::size_t partialsPrepared_ = 0;
    // Last: starts once everything it touches exists.
    BackgroundJob<std::optional<PreparedScan>> job_;
};

}  // namespace subscan::viewer
