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
    update(fraction, {});
}

void ProgressBar::update(double fraction, std::string_view detail) {
    if (!enabled_) {
        return;
    }
    fraction = std::clamp(fraction, 0.0, 1.0);
    const int percent = static_cast<int>(fraction * 100.0);
    if (percent == lastPercent_) {
        return;
    }
    lastPercent_ = percent;
    constexpr int kWidth = 40;
    const int filled = percent * kWidth / 100;
    std::string left;
    if (percent >= 3 && percent < 100) {
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        const auto seconds = static_cast<long>(elapsed * (1.0 - fraction) / fraction);
        left = fmt::format(", {}:{:02} left", seconds / 60, seconds % 60);
    }
    fmt::print(stderr, "\r\033[K{} [{}{}] {:3}%{}{}{}", label_, std::string(filled, '#'),
               std::string(kWidth - filled, '.'), percent, detail.empty() ? "" : " ", detail, left);
    std::fflush(stderr);
}

}  // namespace subscan
