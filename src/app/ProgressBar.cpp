#include "app/ProgressBar.h"

#include <unistd.h>
#include <algorithm>

#include <fmt/format.h>

namespace subscan {

ProgressBar::ProgressBar(std::string label, bool worthShowing)
    : label_(std::move(label)), enabled_(worthShowing && ::isatty(STDERR_FILENO) == 1) {}

ProgressBar::~ProgressBar() {
    if (enabled_ && lastPercent_ >= 0) {
        fmt::print(stderr, "\r\033[K");  // clear the bar so later output starts on a clean line
        std::fflush(stderr);
    }
}

void ProgressBar::update(double fraction) {
    if (!enabled_) {
        return;
    }
    const int percent = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 100.0);
    if (percent == lastPercent_) {
        return;
    }
    lastPercent_ = percent;
    constexpr int kWidth = 40;
    const int filled = percent * kWidth / 100;
    fmt::print(stderr, "\r{} [{}{}] {:3}%", label_, std::string(filled, '#'),
               std::string(kWidth - filled, '.'), percent);
    std::fflush(stderr);
}

}  // namespace subscan
