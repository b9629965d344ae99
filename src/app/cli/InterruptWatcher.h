#pragma once

#include <signal.h>

#include <atomic>
#include <ctime>
#include <stop_token>
#include <thread>

namespace subscan::cli {

/// Ctrl-C and SIGTERM become a flag a long command checks between its steps (it then removes
/// its temporary files and the partial output: index, turntable): the signals are blocked in every
/// thread and a watcher thread waits for them, so no handler runs in the middle of a write.
class InterruptWatcher {
  public:
    InterruptWatcher() {
        sigemptyset(&signals_);
        sigaddset(&signals_, SIGINT);
        sigaddset(&signals_, SIGTERM);
        ::pthread_sigmask(SIG_BLOCK, &signals_, &previous_);
        watcher_ = std::jthread([this](const std::stop_token& stop) {
            const timespec wait{0, 100'000'000};
            while (!stop.stop_requested()) {
                if (::sigtimedwait(&signals_, nullptr, &wait) > 0) {
                    interrupted_ = true;
                }
            }
        });
    }
    ~InterruptWatcher() {
        watcher_.request_stop();
        watcher_.join();
        ::pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
    }
    InterruptWatcher(const InterruptWatcher&) = delete;
    InterruptWatcher& operator=(const InterruptWatcher&) = delete;

    const std::atomic<bool>& interrupted() const { return interrupted_; }

  private:
    sigset_t signals_{};
    sigset_t previous_{};
    std::atomic<bool> interrupted_{false};
    std::jthread watcher_;
};

}  // namespace subscan::cli
