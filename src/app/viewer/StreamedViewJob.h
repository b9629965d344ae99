#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/viewer/BackgroundJob.h"
#include "app/viewer/ScanLoadJob.h"
#include "core/Camera.h"
#include "lod/NodeCache.h"

namespace subscan::viewer {

/// The nodes of a streamed scan that a camera shows within a point budget (lod::selectNodes),
/// loaded and prepared for the renderer on a thread of its own: the window keeps drawing the
/// nodes it has meanwhile, and nothing in a frame waits for the disk. Destroying an unfinished
/// job cancels it and waits for the thread.
class StreamedViewJob {
  public:
    /// `shown`: the nodes on screen now; a view that selects the same ones loads nothing.
    StreamedViewJob(std::shared_ptr<const lod::CachedNodeSource> source, std::string sourceName,
                    const Camera& camera, std::uint64_t pointBudget,
                    std::vector<std::size_t> shown);

    bool finished() const { return job_.finished(); }
    /// Once finished(): the view's nodes prepared, or nullopt where they are the ones shown.
    /// Rethrows a subscan::Error of the load. Call at most once.
    std::optional<PreparedScan> take() { return job_.take(); }

  private:
    std::optional<PreparedScan> load(const std::function<bool()>& cancelled);

    std::shared_ptr<const lod::CachedNodeSource> source_;
    std::string sourceName_;
    Camera camera_;
    std::uint64_t pointBudget_;
    std::vector<std::size_t> shown_;
    // Last: starts once everything it touches exists.
    BackgroundJob<std::optional<PreparedScan>> job_;
};

}  // namespace subscan::viewer
