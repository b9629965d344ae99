#pragma once

#include <chrono>
#include <cstdio>
#include <string>
#include <string_view>

namespace subscan {

/// A one-line progress bar on stderr, shown only when stderr is a terminal and the work is big
/// enough to be worth watching; otherwise every call does nothing.
class ProgressBar {
  public:
    ProgressBar(std::string label, bool worthShowing);
    ~ProgressBar();
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    void update(double fraction);
    /// With what is being done (e.g. "indexing, 44.0 M points") and, once a few per cent are
    /// done, the time left at the rate so far.
    void update(double fraction, std::string_view detail);

  private:
    std::string label_;
    bool enabled_;
    int lastPercent_ = -1;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace subscan
