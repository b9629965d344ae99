#include "app/viewer/StreamedViewJob.h"

#include <new>
#include <utility>

#include "core/Error.h"
#include "lod/NodeSelection.h"

namespace subscan::viewer {

StreamedViewJob::StreamedViewJob(std::shared_ptr<const lod::NodeSource> source,
                                 std::string sourceName, const Camera& camera,
                                 std::uint64_t pointBudget, std::vector<std::size_t> shown)
    : source_(std::move(source)),
      sourceName_(std::move(sourceName)),
      camera_(camera),
      pointBudget_(pointBudget),
      shown_(std::move(shown)),
      thread_([this] { load(); }) {}

StreamedViewJob::~StreamedViewJob() {
    cancelled_.store(true, std::memory_order_relaxed);
    thread_.join();
}

void StreamedViewJob::load() {
    try {
        std::vector<std::size_t> nodes = lod::selectNodes(*source_, camera_, pointBudget_);
        if (nodes != shown_) {
            PreparedScan prepared;
            prepared.source = sourceName_;
            prepared.streamed = source_;
            // The source's own warnings were said when it opened.
            prepared.scan = lod::loadStreamedScan(*source_, nodes, false, [this] {
                return cancelled_.load(std::memory_order_relaxed);
            });
            prepared.nodes = std::move(nodes);
            if (prepareForRenderer(prepared,
                                   [this] { return cancelled_.load(std::memory_order_relaxed); })) {
                result_ = std::move(prepared);
            }
        }
    } catch (const std::bad_alloc&) {
        error_ = std::make_exception_ptr(
            Error(sourceName_ + ": out of memory for the view's points (try a smaller "
                                "point budget)"));
    } catch (...) {
        error_ = std::current_exception();
    }
    finished_.store(true, std::memory_order_release);
}

std::optional<PreparedScan> StreamedViewJob::take() {
    if (error_) {
        std::rethrow_exception(std::exchange(error_, nullptr));
    }
    return std::exchange(result_, std::nullopt);
}

}  // namespace subscan::viewer
