#pragma once

#include <chrono>
#include <cstdio>
#include <string>

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

  private:
    std::string label_;
    bool enabled_;
    int lastPercent_ = -1;
};

}  // namespace subscan
