#pragma once

#include <signal.h>

#include <atomic>
#include <cstdlib>
#include <ctime>
#include <stop_token>
#include <string>
#include <thread>

#include "core/Error.h"

namespace subscan::cli {

/// Thrown once an interrupt stopped a command after it cleaned up: run() prints the sentence,
/// which says what was removed or left, and exits 128 + the signal (130 for Ctrl-C), as the
/// signal's default action would have.
class Interrupted : public Error {
  public:
    Interrupted(const std::string& sentence, int signal) : Error(sentence), signal_(signal) {}
    int exitStatus() const { return 128 + signal_; }

  private:
    int signal_;
};

/// Ctrl-C and SIGTERM end the command at once while it has written nothing; once it has
/// (defer()), they become a flag it checks between its steps, then removes its temporary files
/// and the partial output (index, turntable), and a second one ends it at once. The signals are
/// blocked in every thread (make this before any thread starts) and a watcher thread waits for
/// them, so no handler runs in the middle of a write.
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
                const int signal = ::sigtimedwait(&signals_, nullptr, &wait);
                if (signal <= 0) {
                    continue;
                }
                if (!deferred_ || interrupted_) {
                    std::_Exit(128 + signal);  // as the signal's default action would end it
                }
                signal_ = signal;
                interrupted_ = true;
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

    /// From now on an interrupt is the flag interrupted(): there is something to clean up.
    void defer() { deferred_ = true; }
    const std::atomic<bool>& interrupted() const { return interrupted_; }
    /// What to throw once interrupted() and cleaned up; `sentence` says what was left.
    Interrupted stopped(const std::string& sentence) const { return {sentence, signal_}; }

  private:
    sigset_t signals_{};
    sigset_t previous_{};
    std::atomic<bool> deferred_{false};
    std::atomic<int> signal_{SIGINT};
    std::atomic<bool> interrupted_{false};
    std::jthread watcher_;
};

}  // namespace subscan::cli
