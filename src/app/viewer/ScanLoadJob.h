#pragma once

#include <atomic>
#include <exception>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <glm/vec3.hpp>

#include "core/LocalSpacing.h"
#include "io/ScanLoader.h"

namespace subscan::viewer {

/// A scan as the viewer needs it: the cloud for the GPU upload, its spacing (h and the local
/// spacing) and normals, all made off the render thread.
struct PreparedScan {
    std::string source;
    LoadedScan scan;
    PointSpacing spacing;  // estimatePointSpacing's result (h = 0: the renderer picks one)
    std::vector<glm::vec3> normals;  // normalsFor(cloud, auto): empty where none are estimated
};

/// Loads a scan on a thread of its own so that the window keeps drawing (with a progress bar)
/// while a big file is decoded. Destroying an unfinished job cancels it at the reader's next
/// progress report and waits for the thread.
class ScanLoadJob {
  public:
    explicit ScanLoadJob(std::string source);
    ~ScanLoadJob();
    ScanLoadJob(const ScanLoadJob&) = delete;
    ScanLoadJob& operator=(const ScanLoadJob&) = delete;

    const std::string& source() const { return source_; }
    /// 0..1 while the file is decoded; readers of small files and synthetic scenes report
    /// nothing until they are done.
    double progress() const { return progress_.load(std::memory_order_relaxed); }
    bool finished() const { return finished_.load(std::memory_order_acquire); }
    /// The result once finished(); rethrows the load's subscan::Error. Call at most once.
    PreparedScan take();

  private:
    void load();

    std::string source_;
    std::atomic<double> progress_{0.0};
    std::atomic<bool> finished_{false};
    std::atomic<bool> cancelled_{false};
    std::optional<PreparedScan> result_;
    std::exception_ptr error_;
    std::thread thread_;  // last: starts once everything it touches exists
};

}  // namespace subscan::viewer
