#include "app/viewer/StreamedViewJob.h"

#include <new>
#include <utility>

#include "core/Error.h"
#include "core/LocalSpacing.h"
#include "core/Spacing.h"
#include "lod/NodeSelection.h"

namespace subscan::viewer {

std::uint64_t partialViewPoints(std::uint64_t pointBudget) {
    return pointBudget >= 4 * kAlwaysLocalSpacingPoints ? pointBudget / 4 : 0;
}

std::vector<std::size_t> partialViewEnds(std::span<const lod::StreamedNode> all,
                                         std::span<const std::size_t> nodes,
                                         std::uint64_t partialPoints) {
    std::vector<std::size_t> ends;
    if (partialPoints == 0) {
        return ends;
    }
    std::uint64_t points = 0;
    std::uint64_t next = partialPoints;
    for (std::size_t i = 0; i + 1 < nodes.size(); ++i) {
        points += all[nodes[i]].pointCount;
        if (points >= next) {
            ends.push_back(i + 1);
            next = points + partialPoints;
        }
    }
    return ends;
}

StreamedViewJob::StreamedViewJob(std::shared_ptr<const lod::CachedNodeSource> source,
                                 std::string sourceName, const Camera& camera,
                                 std::uint64_t pointBudget, std::vector<std::size_t> shown,
                                 std::pair<Coloring, UpAxis> coloredBy, std::uint64_t partialPoints)
    : source_(std::move(source)),
      sourceName_(std::move(sourceName)),
      camera_(camera),
      pointBudget_(pointBudget),
      shown_(std::move(shown)),
      coloredBy_(coloredBy),
      partialPoints_(partialPoints),
      job_(sourceName_,
           [this](const std::function<bool()>& cancelled) { return load(cancelled); }) {}

std::optional<PreparedScan> StreamedViewJob::takePartial() {
    const std::lock_guard lock(partialMutex_);
    return std::exchange(partial_, std::nullopt);
}

std::size_t StreamedViewJob::partialsPrepared() const {
    const std::lock_guard lock(partialMutex_);
    return partialsPrepared_;
}

std::optional<PreparedScan> StreamedViewJob::prepare(std::vector<std::size_t> nodes,
                                                     const std::function<bool()>& cancelled,
                                                     bool provisional) const {
    PreparedScan prepared;
    prepared.source = sourceName_;
    prepared.streamed = source_;
    // The source's own warnings were said when it opened.
    prepared.scan = lod::loadStreamedScan(*source_, nodes, false, cancelled);
    prepared.nodes = std::move(nodes);
    if (provisional) {
        // No normals either way: a streamed view estimates none (streamedNormals).
        prepareProvisionally(prepared);
    } else if (!prepareForRenderer(prepared, cancelled)) {
        return std::nullopt;
    }
    try {
        prepared.shownColors =
            pointColors(prepared.scan.cloud, coloredBy_.first, coloredBy_.second);
        prepared.coloredBy = coloredBy_;
    } catch (const Error&) {
        // What the colouring lacks: the viewer says so when it colours the points itself.
    }
    if (cancelled && cancelled()) {
        return std::nullopt;
    }
    return prepared;
}

std::optional<PreparedScan> StreamedViewJob::load(const std::function<bool()>& cancelled) {
    try {
        std::vector<std::size_t> nodes = lod::selectNodes(*source_, camera_, pointBudget_);
        if (nodes == shown_) {
            return std::nullopt;
        }
        // The largest on screen first; each set read again comes from the node cache.
        for (const std::size_t end : partialViewEnds(source_->nodes(), nodes, partialPoints_)) {
            std::optional<PreparedScan> partial =
                prepare(std::vector<std::size_t>(nodes.begin(),
                                                 nodes.begin() + static_cast<std::ptrdiff_t>(end)),
                        cancelled, true);
            if (!partial) {
                return std::nullopt;
            }
            const std::lock_guard lock(partialMutex_);
            partial_ = std::move(partial);
            ++partialsPrepared_;
        }
        return prepare(std::move(nodes), cancelled, false);
    } catch (const std::bad_alloc&) {
        throw Error(sourceName_ +
                    ": out of memory for the view's points (try a smaller "
                    "point budget)");
    }
}

}  // namespace subscan::viewer
