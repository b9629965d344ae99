#pragma once

#include <atomic>
#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "core/Error.h"

namespace subscan::viewer {

/// Work done on a thread of its own while the window keeps drawing (ScanLoadJob,
/// StreamedViewJob): the render loop polls finished() and then take()s the result, or the
/// work's error. Destroying an unfinished job turns the work's `cancelled` true and waits for
/// the thread.
template <class Result>
class BackgroundJob {
  public:
    /// Starts `work` (Result(const std::function<bool()>& cancelled)) on its thread. `name`
    /// names the job in its one error of misuse. Whatever of its owner the work reads must
    /// exist before: an owner declares its job after those members.
    template <class Work>
    BackgroundJob(std::string name, Work work)
        : name_(std::move(name)), thread_([this, work = std::move(work)]() mutable {
              try {
                  result_ = work(std::function<bool()>(
                      [this] { return cancelled_.load(std::memory_order_relaxed); }));
              } catch (...) {
                  error_ = std::current_exception();
              }
              finished_.store(true, std::memory_order_release);
          }) {}
    ~BackgroundJob() {
        cancelled_.store(true, std::memory_order_relaxed);
        thread_.join();
    }
    BackgroundJob(const BackgroundJob&) = delete;
    BackgroundJob& operator=(const BackgroundJob&) = delete;

    bool finished() const { return finished_.load(std::memory_order_acquire); }
    /// Once finished(): the result; rethrows the work's error. Call at most once.
    Result take() {
        if (error_) {
            std::rethrow_exception(std::exchange(error_, nullptr));
        }
        if (!result_) {
            throw Error(name_ + ": the result was already taken");
        }
        Result result = std::move(*result_);
        result_.reset();
        return result;
    }

  private:
    std::string name_;
    std::atomic<bool> finished_{false};
    std::atomic<bool> cancelled_{false};
    std::optional<Result> result_;
    std::exception_ptr error_;
    std::thread thread_;  // last: starts once everything it touches exists
};

}  // namespace subscan::viewer
