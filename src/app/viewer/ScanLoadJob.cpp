#include "app/viewer/ScanLoadJob.h"

#include <new>
#include <utility>

#include "core/Error.h"
#include "render/Renderer.h"

namespace subscan::viewer {

namespace {

/// Thrown from the progress callback to abandon a load nobody waits for any more.
struct LoadCancelled {};

}  // namespace

ScanLoadJob::ScanLoadJob(std::string source)
    : source_(std::move(source)), thread_([this] { load(); }) {}

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
        PreparedScan prepared{source_, loadScan(source_, reportProgress), {}};
        prepared.spacing = estimatePointSpacing(prepared.scan.cloud);
        // As Renderer::prepareNormals does for `auto`, here off the render thread.
        prepared.normals = normalsFor(prepared.scan.cloud, NormalSource::Auto, [this] {
            return cancelled_.load(std::memory_order_relaxed);
        });
        if (cancelled_.load(std::memory_order_relaxed)) {
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
