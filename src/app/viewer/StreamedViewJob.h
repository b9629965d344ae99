#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

#include "app/viewer/ScanLoadJob.h"
#include "core/Camera.h"
#include "lod/NodeSource.h"

namespace subscan::viewer {

/// The nodes of a streamed scan that a camera shows within a point budget (lod::selectNodes),
/// loaded and prepared for the renderer on a thread of its own: the window keeps drawing the
/// nodes it has meanwhile, and nothing in a frame waits for the disk. Destroying an unfinished
/// job cancels it and waits for the thread.
class StreamedViewJob {
  public:
    /// `shown`: the nodes on screen now; a view that selects the same ones loads nothing.
    StreamedViewJob(std::shared_ptr<const lod::NodeSource> source, std::string sourceName,
                    const Camera& camera, std::uint64_t pointBudget,
                    std::vector<std::size_t> shown);
    ~StreamedViewJob();
    StreamedViewJob(const StreamedViewJob&) = delete;
    StreamedViewJob& operator=(const StreamedViewJob&) = delete;

    bool finished() const { return finished_.load(std::memory_order_acquire); }
    /// Once finished(): the view's nodes prepared, or nullopt where they are the ones shown.
    /// Rethrows a subscan::Error of the load. Call at most once.
    std::optional<PreparedScan> take();

  private:
    void load();

    std::shared_ptr<const lod::NodeSource> source_;
    std::string sourceName_;
    Camera camera_;
    std::uint64_t pointBudget_;
    std::vector<std::size_t> shown_;
    std::atomic<bool> finished_{false};
    std::atomic<bool> cancelled_{false};
    std::optional<PreparedScan> result_;
    std::exception_ptr error_;
    std::thread thread_;  // last: starts once everything it touches exists
};

}  // namespace subscan::viewer
