#include "app/viewer/StreamedViewJob.h"

#include <new>
#include <utility>

#include "core/Error.h"
#include "lod/NodeSelection.h"

namespace subscan::viewer {

StreamedViewJob::StreamedViewJob(std::shared_ptr<const lod::CachedNodeSource> source,
                                 std::string sourceName, const Camera& camera,
                                 std::uint64_t pointBudget, std::vector<std::size_t> shown)
    : source_(std::move(source)),
      sourceName_(std::move(sourceName)),
      camera_(camera),
      pointBudget_(pointBudget),
      shown_(std::move(shown)),
      job_(sourceName_,
           [this](const std::function<bool()>& cancelled) { return load(cancelled); }) {}

std::optional<PreparedScan> StreamedViewJob::load(const std::function<bool()>& cancelled) {
    try {
        std::vector<std::size_t> nodes = lod::selectNodes(*source_, camera_, pointBudget_);
        if (nodes == shown_) {
            return std::nullopt;
        }
        PreparedScan prepared;
        prepared.source = sourceName_;
        prepared.streamed = source_;
        // The source's own warnings were said when it opened.
        prepared.scan = lod::loadStreamedScan(*source_, nodes, false, cancelled);
        prepared.nodes = std::move(nodes);
        if (!prepareForRenderer(prepared, cancelled)) {
            return std::nullopt;
        }
        return prepared;
    } catch (const std::bad_alloc&) {
        throw Error(sourceName_ +
                    ": out of memory for the view's points (try a smaller "
                    "point budget)");
    }
}

}  // namespace subscan::viewer
