#include "app/viewer/ScanLoadJob.h"

#include <new>
#include <utility>

#include "core/Error.h"
#include "lod/NodeSelection.h"
#include "render/Renderer.h"

namespace subscan::viewer {

namespace {

/// Thrown from the progress callback to abandon a load nobody waits for any more.
struct LoadCancelled {};

}  // namespace

ScanLoadJob::ScanLoadJob(std::string source, lod::LodMode lod)
    : source_(std::move(source)), lod_(lod), thread_([this] { load(); }) {}

ScanLoadJob::~ScanLoadJob() {
    cancelled_.store(true, std::memory_order_relaxed);
    thread_.join();
}

void ScanLoadJob::load() {
    const auto reportProgress = [this](double fraction) {
        if (cancelled_.load(std::memory_order_relaxed)) {
            throw LoadCancelled{};
        }
        progress_.store(fraction, std::memory_order_relaxed);
    };
    try {
        PreparedScan prepared;
        prepared.source = source_;
        prepared.streamed = lod::openStreamed(source_, lod_);
        if (prepared.streamed) {
            prepared.scan = lod::loadStreamedOverview(*prepared.streamed, &prepared.nodes);
        } else {
            prepared.scan = loadScan(source_, reportProgress);
        }
        if (!prepareForRenderer(prepared,
                                [this] { return cancelled_.load(std::memory_order_relaxed); })) {
            throw LoadCancelled{};
        }
        result_ = std::move(prepared);
    } catch (const LoadCancelled&) {
        error_ = std::make_exception_ptr(Error(source_ + ": loading was cancelled"));
    } catch (const std::bad_alloc&) {
        error_ = std::make_exception_ptr(
            Error(source_ + ": out of memory (the scan is too large for this machine)"));
    } catch (...) {
        error_ = std::current_exception();
    }
    finished_.store(true, std::memory_order_release);
}

bool prepareForRenderer(PreparedScan& prepared, const std::function<bool()>& cancelled) {
    prepared.spacing = estimatePointSpacing(prepared.scan.cloud);
    prepared.normals = normalsFor(
        prepared.scan.cloud,
        prepared.streamed ? streamedNormals(NormalSource::Auto) : NormalSource::Auto, cancelled);
    return !cancelled();
}

PreparedScan ScanLoadJob::take() {
    if (error_) {
        std::rethrow_exception(std::exchange(error_, nullptr));
    }
    if (!result_) {
        throw Error(source_ + ": the scan was already taken");
    }
    PreparedScan prepared = std::move(*result_);
    result_.reset();
    return prepared;
}

}  // namespace subscan::viewer
