#pragma once

#include <chrono>
#include <string>
#include <string_view>
#include <vector>

#include "gpu/GlContext.h"
#include "gpu/GlObjects.h"

namespace subscan {

struct PassTiming {
    std::string pass;
    double milliseconds = 0.0;
};

enum class TimingMode {
    Auto,            // GPU timer queries on hardware, glFinish + CPU clock on software renderers
    GpuQueries,      // GL_TIME_ELAPSED around each pass; no stall between passes
    FinishAndClock,  // glFinish before and after each pass, steady_clock in between
};

/// Times the passes of one frame. begin()/end() bracket each pass; collect() returns the
/// frame's timings (waiting for the queries) and readies the timer for the next frame.
class PassTimer {
  public:
    PassTimer(const GlCapabilities& capabilities, TimingMode mode);

    void begin(std::string_view pass);
    void end();
    std::vector<PassTiming> collect();
    bool usesGpuQueries() const { return useQueries_; }

  private:
    bool useQueries_;
    std::vector<std::string> names_;
    std::vector<TimerQuery> queries_;  // one per pass slot, reused frame to frame
    std::vector<double> cpuMilliseconds_;
    std::chrono::steady_clock::time_point started_;
};

}  // namespace subscan
