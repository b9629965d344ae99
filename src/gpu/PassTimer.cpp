#include "gpu/PassTimer.h"

namespace subscan {

PassTimer::PassTimer(const GlCapabilities& capabilities, TimingMode mode)
    : useQueries_(mode == TimingMode::GpuQueries ||
                  (mode == TimingMode::Auto && !capabilities.software)) {}

void PassTimer::begin(std::string_view pass) {
    names_.emplace_back(pass);
    if (useQueries_) {
        if (queries_.size() < names_.size()) {
            queries_.emplace_back();
        }
        glBeginQuery(GL_TIME_ELAPSED, queries_[names_.size() - 1].id());
    } else {
        glFinish();
        started_ = std::chrono::steady_clock::now();
    }
}

void PassTimer::end() {
    if (useQueries_) {
        glEndQuery(GL_TIME_ELAPSED);
    } else {
        glFinish();
        cpuMilliseconds_.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started_)
                .count());
    }
}

std::vector<PassTiming> PassTimer::collect() {
    std::vector<PassTiming> timings;
    for (std::size_t i = 0; i < names_.size(); ++i) {
        double milliseconds = 0.0;
        if (useQueries_) {
            GLuint64 nanoseconds = 0;
            glGetQueryObjectui64v(queries_[i].id(), GL_QUERY_RESULT, &nanoseconds);
            milliseconds = static_cast<double>(nanoseconds) * 1e-6;
        } else {
            milliseconds = cpuMilliseconds_[i];
        }
        timings.push_back({names_[i], milliseconds});
    }
    names_.clear();
    cpuMilliseconds_.clear();
    return timings;
}

}  // namespace subscan
